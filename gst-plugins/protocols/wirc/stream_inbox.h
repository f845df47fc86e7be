// The receiving end of one camera's stream for a thread that waits on it
// (wircsrc's streaming thread): the UDP socket, the StreamReceiver that
// turns its datagrams into frames, and the wake-ups other threads give it
// (stop waiting, the link changed, end the stream). wait() returns at the
// first of them, a whole frame, or the deadline.
#pragma once

#include <sys/socket.h>

#include <chrono>
#include <ctime>
#include <deque>
#include <memory>
#include <optional>
#include <string>

#include "common/socket.h"
#include "wirc/stream_receiver.h"

namespace wircam::wirc {

class StreamInbox {
 public:
  using Clock = std::chrono::steady_clock;
  // The device sends whole frames in bursts of up to 64 KB datagrams.
  static constexpr int kReceiveBufferBytes = 8 << 20;

  enum class Wake { Frame, Interrupted, LinkChanged, EndRequested, Deadline };

  StreamInbox();

  // Binds `port` (0: any free one) with a kReceiveBufferBytes buffer where
  // the kernel allows it; frames time out after `config.frameTimeout`.
  // Returns why not, if it cannot.
  std::optional<std::string> open(uint16_t port, FrameAssemblerConfig config);
  void close();
  bool isOpen() const { return receiver_.has_value(); }
  uint16_t port() const;
  // What the kernel granted of kReceiveBufferBytes.
  int receiveBufferBytes() const;
  StreamReceiver& receiver() { return *receiver_; }

  // From any thread. interrupt() holds until clearInterrupt(); an end
  // request until clearEndRequest() (kept across open/close, so that it
  // never races a close).
  void interrupt();
  void clearInterrupt();
  void linkChanged();
  void requestEnd();
  void clearEndRequest();

  // Waits until a frame is whole, a wake-up, or `deadline`; frames the
  // deadline expires are given up on the way.
  Wake wait(Clock::time_point deadline);
  std::optional<AssembledFrame> takeFrame();

  // A datagram's arrival from the kernel's stamp on `message`
  // (SCM_TIMESTAMPNS, wall clock), carried onto the steady clock by its age
  // at `now`/`wallNow`; `now` if it has none, or an implausible one.
  static Clock::time_point arrivalOf(const msghdr& message, Clock::time_point now,
                                     const timespec& wallNow);
  static constexpr auto kLongestPlausibleAge = std::chrono::seconds(5);

 private:
  void receiveBatch();
  void giveBackUnusedSlots(size_t used, Clock::time_point now);

  UniqueFd socket_;
  UniqueFd interrupt_;
  UniqueFd linkChanged_;
  UniqueFd endRequest_;
  std::optional<StreamReceiver> receiver_;
  std::deque<AssembledFrame> ready_;

  // Datagrams of up to 64 KB, a batch at a time, each in a page-aligned
  // slot of a region mapped lazily: only the pages datagrams fill become
  // resident. The slots a burst filled (a busy machine let the socket
  // fill) are given back once unused for a while: bursts at the start of
  // 256 cameras left 300 KB resident a camera, for good.
  struct Unmap {
    void operator()(uint8_t* slots) const;
  };
  std::unique_ptr<uint8_t, Unmap> slots_;
  size_t residentSlots_ = 0;      // the most a batch has filled since the last give-back
  size_t recentlyUsedSlots_ = 0;  // the most a batch has filled in this window
  Clock::time_point slotsWindowStart_{};
};

}  // namespace wircam::wirc
