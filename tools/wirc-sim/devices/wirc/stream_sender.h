// The device side of one MJPEG stream: cuts each JPEG frame into datagrams
// as a WiRC device does and sends them to one receiver, optionally through
// network impairments (seeded, so a test run can be repeated exactly).
#pragma once

#include <cstdint>
#include <deque>
#include <random>
#include <span>
#include <vector>

#include "common/socket.h"

namespace wircam::wirc {

struct Impairments {
  double loss = 0;            // probability that a datagram is lost
  double burstLoss = 0;       // probability that a loss burst starts at a datagram
  int burstLength = 5;        // datagrams lost in one burst
  double duplication = 0;     // probability that a datagram is sent twice
  int reorderDepth = 0;       // datagrams held back and released in random order
  size_t fragmentJitter = 0;  // fragment sizes vary by up to ± this many bytes
  bool reservedBits = false;  // set the version's reserved bits 31..17
  double strayRate = 0;       // per frame: a forged datagram from another port
  // When set, every stream goes to this port of the receiver's host instead
  // of the one STST named: a NAT or firewall in between that maps it wrong.
  uint16_t misdirectPort = 0;
  uint32_t startFrameNumber = 0;
  uint32_t seed = 1;
};

struct StreamSenderStats {
  uint64_t frames = 0;
  uint64_t framesWhole = 0;  // frames none of whose packets was dropped on purpose
  uint64_t datagrams = 0;    // put on the wire, duplicates included
  uint64_t dropped = 0;      // lost on purpose (loss, burst loss)
  uint64_t duplicated = 0;
  uint64_t stray = 0;
  uint64_t sendErrors = 0;  // the kernel refused a datagram
};

class StreamSender {
 public:
  // `socket` sends the stream, `straySocket` (another port) the forgeries;
  // both stay owned by the caller.
  StreamSender(int socket, int straySocket, SocketAddress receiver, size_t fragmentSize,
               const Impairments& impairments);

  // Sends one frame; returns its frame number.
  uint32_t sendFrame(std::span<const uint8_t> jpeg);
  // Releases datagrams still held back for reordering.
  void flush();

  const SocketAddress& receiver() const { return receiver_; }
  const StreamSenderStats& stats() const { return stats_; }

 private:
  // False when the impairments dropped the datagram.
  bool emit(std::vector<uint8_t>&& datagram);
  void put(const std::vector<uint8_t>& datagram);
  bool chance(double probability);

  int socket_;
  int straySocket_;
  SocketAddress receiver_;
  size_t fragmentSize_;
  Impairments impairments_;
  std::mt19937 random_;
  uint32_t frameNumber_;
  int burstLeft_ = 0;
  std::deque<std::vector<uint8_t>> heldBack_;
  StreamSenderStats stats_;
};

}  // namespace wircam::wirc
