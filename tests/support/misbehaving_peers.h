// TCP peers that a vehicle link must survive without hanging, on loopback
// ephemeral ports: one that accepts and never answers, and one whose
// accept queue is full so that a connect never completes.
#pragma once

#include <cstdint>
#include <thread>
#include <vector>

#include "common/socket.h"

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

// Answers every connection's first bytes with ERR (command TL, `code`), as
// a real WiRC answers a second connection from one address (6, busy).
class RefusingPeer {
 public:
  explicit RefusingPeer(uint16_t code);
  ~RefusingPeer();
  uint16_t port() const { return port_; }

 private:
  UniqueFd listener_;
  UniqueFd wake_;
  uint16_t port_ = 0;
  std::thread thread_;
};

// A loopback port nothing listens on (bound, then closed).
uint16_t deadPort();

}  // namespace wircam::testing
