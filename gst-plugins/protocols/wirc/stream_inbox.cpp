#include "wirc/stream_inbox.h"

#include <poll.h>
#include <sys/eventfd.h>
#include <sys/mman.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <ctime>
#include <new>

namespace wircam::wirc {

namespace {

constexpr size_t kBatch = 16;  // datagrams per recvmmsg
// A slot a datagram, on page boundaries (kMaxDatagramSize rounded up).
constexpr size_t kSlotBytes = 65536;
static_assert(kSlotBytes >= kMaxDatagramSize);
constexpr size_t kSlotsBytes = kBatch * kSlotBytes;
// Slots always kept resident: a 720p frame is two datagrams.
constexpr size_t kKeptSlots = 2;
// How long a batch's slots stay resident unused before they are given back.
constexpr auto kSlotsWindow = std::chrono::seconds(1);

uint8_t* mapSlots() {
  void* slots =
      mmap(nullptr, kSlotsBytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (slots == MAP_FAILED) throw std::bad_alloc();
  return static_cast<uint8_t*>(slots);
}

UniqueFd newEventFd() { return UniqueFd(eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK)); }

void signal(const UniqueFd& fd) {
  uint64_t one = 1;
  if (fd.valid() && write(fd.get(), &one, sizeof one) < 0) {
    // Only fails when the counter is saturated: the reader wakes anyway.
  }
}

void drain(const UniqueFd& fd) {
  uint64_t value;
  if (fd.valid() && read(fd.get(), &value, sizeof value) < 0) {
    // Nothing was pending: fine.
  }
}

bool readable(const pollfd& fd) { return (fd.revents & POLLIN) != 0; }

}  // namespace

StreamInbox::StreamInbox()
    : interrupt_(newEventFd()),
      linkChanged_(newEventFd()),
      endRequest_(newEventFd()),
      slots_(mapSlots()) {}

void StreamInbox::Unmap::operator()(uint8_t* slots) const { munmap(slots, kSlotsBytes); }

std::optional<std::string> StreamInbox::open(uint16_t port, FrameAssemblerConfig config) {
  auto socket = bindUdp(*SocketAddress::resolve("", port));
  if (!socket) return socket.error();
  socket_ = std::move(*socket);
  int size = kReceiveBufferBytes;
  if (setsockopt(socket_.get(), SOL_SOCKET, SO_RCVBUFFORCE, &size, sizeof size) != 0)
    setsockopt(socket_.get(), SOL_SOCKET, SO_RCVBUF, &size, sizeof size);
  // The kernel stamps each datagram as it arrives: a frame's time is when
  // its first packet came, not when a busy machine let this thread read it.
  int on = 1;
  setsockopt(socket_.get(), SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof on);
  drain(linkChanged_);
  receiver_.emplace(config);
  ready_.clear();
  return std::nullopt;
}

void StreamInbox::close() {
  ready_.clear();
  receiver_.reset();
  socket_.reset();
}

uint16_t StreamInbox::port() const { return localAddress(socket_.get()).port(); }

int StreamInbox::receiveBufferBytes() const {
  int granted = 0;
  socklen_t length = sizeof granted;
  getsockopt(socket_.get(), SOL_SOCKET, SO_RCVBUF, &granted, &length);
  return granted;
}

void StreamInbox::interrupt() { signal(interrupt_); }
void StreamInbox::clearInterrupt() { drain(interrupt_); }
void StreamInbox::linkChanged() { signal(linkChanged_); }
void StreamInbox::requestEnd() { signal(endRequest_); }
void StreamInbox::clearEndRequest() { drain(endRequest_); }

StreamInbox::Wake StreamInbox::wait(Clock::time_point deadline) {
  if (!ready_.empty()) return Wake::Frame;
  // An open frame's timeout may come before the caller's deadline.
  if (auto expiry = receiver_->nextDeadline()) deadline = std::min(deadline, *expiry);
  auto left = std::chrono::ceil<std::chrono::milliseconds>(deadline - Clock::now()).count();
  std::array<pollfd, 4> fds = {
      pollfd{socket_.get(), POLLIN, 0}, pollfd{interrupt_.get(), POLLIN, 0},
      pollfd{linkChanged_.get(), POLLIN, 0}, pollfd{endRequest_.get(), POLLIN, 0}};
  ::poll(fds.data(), fds.size(), static_cast<int>(std::max<int64_t>(left, 0)));
  if (readable(fds[1])) return Wake::Interrupted;
  if (readable(fds[3])) return Wake::EndRequested;
  // A login tells this inbox before it sends STST, and the device streams at
  // once: the caller follows the device before its first datagrams are read
  // (they wait in the socket), or they would come from a device not yet
  // followed and be dropped as foreign.
  if (readable(fds[2])) {
    drain(linkChanged_);
    return Wake::LinkChanged;
  }
  if (readable(fds[0])) receiveBatch();
  receiver_->expire(Clock::now(),
                    [&](AssembledFrame&& frame) { ready_.push_back(std::move(frame)); });
  return ready_.empty() ? Wake::Deadline : Wake::Frame;
}

std::optional<AssembledFrame> StreamInbox::takeFrame() {
  if (ready_.empty()) return std::nullopt;
  AssembledFrame frame = std::move(ready_.front());
  ready_.pop_front();
  return frame;
}

// Whatever datagrams are queued, up to a batch, into the receiver, each at
// its arrival: the kernel's stamp (wall clock) carried onto the steady
// clock by its age now.
void StreamInbox::receiveBatch() {
  std::array<mmsghdr, kBatch> headers{};
  std::array<iovec, kBatch> vectors{};
  std::array<sockaddr_in, kBatch> sources{};
  std::array<std::array<char, CMSG_SPACE(sizeof(timespec))>, kBatch> stamps{};
  for (size_t i = 0; i < kBatch; ++i) {
    vectors[i] = {slots_.get() + i * kSlotBytes, kMaxDatagramSize};
    headers[i].msg_hdr.msg_iov = &vectors[i];
    headers[i].msg_hdr.msg_iovlen = 1;
    headers[i].msg_hdr.msg_name = &sources[i];
    headers[i].msg_hdr.msg_namelen = sizeof sources[i];
    headers[i].msg_hdr.msg_control = stamps[i].data();
    headers[i].msg_hdr.msg_controllen = stamps[i].size();
  }
  int count = recvmmsg(socket_.get(), headers.data(), kBatch, MSG_DONTWAIT, nullptr);
  auto now = Clock::now();
  timespec wallNow{};
  clock_gettime(CLOCK_REALTIME, &wallNow);
  for (int i = 0; i < count; ++i) {
    receiver_->push(SocketAddress(sources[i]),
                    {static_cast<const uint8_t*>(vectors[i].iov_base), headers[i].msg_len},
                    arrivalOf(headers[i].msg_hdr, now, wallNow),
                    [&](AssembledFrame&& frame) { ready_.push_back(std::move(frame)); });
  }
  if (count > 0) giveBackUnusedSlots(static_cast<size_t>(count), now);
}

// Slots a burst filled and no batch has needed for kSlotsWindow go back to
// the system (the receiver has copied what they held). Not at once: a
// stream whose batches often hold a few datagrams (720p/30 on a busy
// thread) would fault its slots in again and again (measured: wircsrc's
// thread at 720p then cost twice as much).
void StreamInbox::giveBackUnusedSlots(size_t used, Clock::time_point now) {
  residentSlots_ = std::max(residentSlots_, used);
  recentlyUsedSlots_ = std::max(recentlyUsedSlots_, used);
  if (now - slotsWindowStart_ < kSlotsWindow) return;
  size_t keep = std::max(recentlyUsedSlots_, kKeptSlots);
  if (residentSlots_ > keep) {
    madvise(slots_.get() + keep * kSlotBytes, (residentSlots_ - keep) * kSlotBytes, MADV_DONTNEED);
    residentSlots_ = keep;
  }
  recentlyUsedSlots_ = 0;
  slotsWindowStart_ = now;
}

StreamInbox::Clock::time_point StreamInbox::arrivalOf(const msghdr& message, Clock::time_point now,
                                                      const timespec& wallNow) {
  for (cmsghdr* c = CMSG_FIRSTHDR(&message); c; c = CMSG_NXTHDR(const_cast<msghdr*>(&message), c)) {
    if (c->cmsg_level != SOL_SOCKET || c->cmsg_type != SCM_TIMESTAMPNS) continue;
    timespec stamp;
    std::memcpy(&stamp, CMSG_DATA(c), sizeof stamp);
    auto age = std::chrono::seconds(wallNow.tv_sec - stamp.tv_sec) +
               std::chrono::nanoseconds(wallNow.tv_nsec - stamp.tv_nsec);
    // A wall clock stepped meanwhile (NTP) would make nonsense of the age:
    // only a plausible one is taken.
    if (age < Clock::duration::zero() || age > kLongestPlausibleAge) return now;
    return now - std::chrono::duration_cast<Clock::duration>(age);
  }
  return now;
}

}  // namespace wircam::wirc
