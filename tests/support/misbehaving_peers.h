// TCP peers that a vehicle link must survive without hanging, on loopback
// ephemeral ports: one that accepts and never answers, and one whose
// accept queue is full so that a connect never completes.
#pragma once

#include <atomic>
#include <cstdint>
#include <mutex>
#include <thread>
#include <vector>

#include "common/socket.h"
#include "wirc/messages.h"

namespace wircam::testing {

// Accepts connections (the kernel does it: the backlog is never drained)
// and never sends a byte.
class SilentPeer {
 public:
  SilentPeer();
  uint16_t port() const { return port_; }

 private:
  UniqueFd listener_;
  uint16_t port_ = 0;
};

// Listens with a backlog it fills itself, so further SYNs are dropped and a
// connect stays pending until its own deadline.
class FullAcceptQueuePeer {
 public:
  FullAcceptQueuePeer();
  uint16_t port() const { return port_; }

 private:
  UniqueFd listener_;
  std::vector<UniqueFd> fillers_;
  uint16_t port_ = 0;
};

// A fake WiRC device that plays a script on each connection it accepts:
// once the transmitter's login (TL) arrives, the scripted chunks go out
// 20 ms apart, then `flood` over and over until the transmitter hangs up,
// and `statusReports` PSD datagrams to the TL's status port. What the
// transmitter sends is kept (stats()). Enough to be every kind of broken
// device the real one and the simulator are not.
struct PeerScript {
  std::vector<std::vector<uint8_t>> chunks;
  std::vector<uint8_t> flood;
  int statusReports = 0;
};

class ScriptedPeer {
 public:
  explicit ScriptedPeer(PeerScript script = {});
  ~ScriptedPeer();
  // A new script for the connections to come (one may need controlPort()).
  void play(PeerScript script);
  // A WST naming this peer's control port, as a scripted login answer.
  std::vector<uint8_t> wst(uint8_t connectionId = 1) const;
  uint16_t port() const { return port_; }
  // Where the transmitter should send PCD: give it in the scripted WST.
  uint16_t controlPort() const { return localAddress(control_.get()).port(); }
  int controlSocket() const { return control_.get(); }
  int connections() const { return connections_; }

 private:
  void serve(UniqueFd connection);

  std::mutex mutex_;  // guards script_
  PeerScript script_;
  UniqueFd listener_;
  UniqueFd control_;  // UDP: PCD arrive here
  UniqueFd wake_;
  uint16_t port_ = 0;
  std::atomic<int> connections_{0};
  std::thread thread_;
};

// The scripted device's messages as bytes.
std::vector<uint8_t> bytesOf(const wirc::Message& message);
// A message frame with any body, CRC filled in: for what encode() refuses
// to write (control bytes in a name, ...).
std::vector<uint8_t> framed(uint8_t command, const std::vector<uint8_t>& body);

// A loopback port nothing listens on (bound, then closed).
uint16_t deadPort();

}  // namespace wircam::testing
