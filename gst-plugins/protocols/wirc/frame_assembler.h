// Reassembles WiRC MJPEG datagrams into whole JPEG frames. A frame is emitted
// only when every byte from 0 to the end named by its last packet has arrived
// and all overlapping copies agreed; anything else is counted and dropped.
// Frames come out in frame-number order (serial arithmetic, so the counter may
// wrap at 2^32). Memory is bounded by maxFramesInFlight × maxFrameBytes.
// Packets never allocate; a frame's buffer is allocated once, unless the
// caller hands emitted buffers back through recycle() (wirc-cli does; wircsrc
// gives each frame's memory to its GstBuffer instead).
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <vector>

#include "wirc/frame_buffer.h"
#include "wirc/mjpeg_packet.h"

namespace wircam::wirc {

struct FrameAssemblerConfig {
  // Largest frame accepted; a packet reaching past it drops its frame.
  size_t maxFrameBytes = 4 * 1024 * 1024;
  // Frames assembled at once; a newer frame evicts the oldest incomplete one.
  size_t maxFramesInFlight = 8;
  // How long an incomplete frame may wait for its missing packets.
  std::chrono::milliseconds frameTimeout{200};
  // How many frame numbers a completed frame may be ahead of an older,
  // incomplete one before that one is given up. 0 = never hold a complete
  // frame back (lowest latency); larger values let reordered frames through.
  uint32_t reorderWindow = 0;
  // A packet for a frame at most this far behind the newest frame already
  // emitted or dropped is late and dropped; further behind means the sender
  // restarted its frame counter, and the assembler starts over.
  uint32_t lateWindow = 16;
};

struct AssembledFrame {
  uint32_t number = 0;
  FrameBuffer data;  // exactly the JPEG bytes
  std::chrono::steady_clock::time_point firstPacketTime;
  bool discont = false;  // a frame was lost (or this is the first)
};

// One counter per reason a packet or frame was not delivered.
struct AssemblerStats {
  uint64_t packets = 0;       // datagrams offered, valid or not
  uint64_t payloadBytes = 0;  // payload bytes of valid packets
  uint64_t keepalives = 0;
  uint64_t packetsInvalid = 0;    // header unparseable (size, version, length)
  uint64_t packetsDuplicate = 0;  // bytes already received, and equal
  uint64_t packetsLate = 0;       // for a frame already emitted or dropped
  uint64_t packetsEmpty = 0;      // zero-length, not the last packet
  uint64_t framesComplete = 0;
  uint64_t framesTimedOut = 0;          // missing packets after frameTimeout
  uint64_t framesSuperseded = 0;        // a newer frame completed past reorderWindow
  uint64_t framesEvicted = 0;           // too many frames in flight
  uint64_t framesOversize = 0;          // offset + length beyond maxFrameBytes
  uint64_t framesOverlapMismatch = 0;   // two copies of the same bytes differ
  uint64_t framesLastFlagConflict = 0;  // last-packet flags name different ends
  uint64_t framesNotJpeg = 0;           // complete, but no JPEG SOI marker
  uint64_t framesAbandoned = 0;         // in flight when the sender restarted
  uint64_t senderRestarts = 0;

  uint64_t framesDropped() const {
    return framesTimedOut + framesSuperseded + framesEvicted + framesOversize +
           framesOverlapMismatch + framesLastFlagConflict + framesNotJpeg + framesAbandoned;
  }
};

class FrameAssembler {
 public:
  using Clock = std::chrono::steady_clock;
  using FrameHandler = std::function<void(AssembledFrame&&)>;

  explicit FrameAssembler(FrameAssemblerConfig config = {});

  // One UDP payload as received. Emits through onFrame every frame this
  // completes or unblocks, oldest first.
  void pushDatagram(std::span<const uint8_t> datagram, Clock::time_point now,
                    const FrameHandler& onFrame);
  void pushPacket(const MjpegPacket& packet, Clock::time_point now, const FrameHandler& onFrame);

  // Gives up frames older than frameTimeout; call it when no packet came.
  void expire(Clock::time_point now, const FrameHandler& onFrame);

  // The earliest time expire() has something to do, if any frame is open.
  std::optional<Clock::time_point> nextDeadline() const;

  // Hands an emitted frame's buffer back so later frames reuse its memory.
  void recycle(FrameBuffer&& buffer);

  // Forgets all frames in flight and the frame-number history (counters stay).
  void reset();

  const AssemblerStats& stats() const { return stats_; }
  const FrameAssemblerConfig& config() const { return config_; }

 private:
  struct Interval {
    uint32_t begin;
    uint32_t end;
  };

  struct Slot {
    bool active = false;
    bool complete = false;
    uint32_t number = 0;
    Clock::time_point firstPacketTime;
    std::optional<uint32_t> totalSize;  // known once a last packet arrived
    FrameBuffer buffer;
    std::vector<Interval> received;  // sorted, disjoint, not touching
  };

  enum class FragmentResult { Added, Duplicate, Mismatch };

  Slot* findSlot(uint32_t number);
  Slot* openSlot(uint32_t number, Clock::time_point now);
  Slot* oldestActive();
  Slot* newestComplete();
  FragmentResult addFragment(Slot& slot, uint32_t offset, std::span<const uint8_t> payload);
  bool isComplete(const Slot& slot) const;
  void drop(Slot& slot, uint64_t& reason);
  void emit(Slot& slot, const FrameHandler& onFrame);
  void flush(const FrameHandler& onFrame);
  void markResolved(uint32_t number);
  void release(Slot& slot);

  FrameAssemblerConfig config_;
  std::vector<Slot> slots_;
  std::vector<FrameBuffer> spareBuffers_;
  // Newest frame number emitted or dropped: packets behind it are late.
  std::optional<uint32_t> lastResolved_;
  std::optional<uint32_t> lastEmitted_;
  bool discontPending_ = true;
  size_t largestRecentFrame_ = 0;
  AssemblerStats stats_;
};

}  // namespace wircam::wirc
