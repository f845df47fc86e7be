#include "wirc/frame_assembler.h"

#include <algorithm>
#include <cstring>

namespace wircam::wirc {

namespace {

// Serial-number order over the 32-bit frame counter, so 0 follows 2^32 - 1.
bool isNewer(uint32_t a, uint32_t b) { return static_cast<int32_t>(a - b) > 0; }

// Room for this many separate holes per frame before the list allocates.
constexpr size_t kExpectedIntervals = 64;

bool startsWithJpegSoi(const FrameBuffer& buffer) {
  return buffer.size() >= 2 && buffer.data()[0] == 0xFF && buffer.data()[1] == 0xD8;
}

}  // namespace

FrameAssembler::FrameAssembler(FrameAssemblerConfig config) : config_(config) {
  config_.maxFramesInFlight = std::max<size_t>(config_.maxFramesInFlight, 1);
  slots_.resize(config_.maxFramesInFlight);
  for (auto& slot : slots_) slot.received.reserve(kExpectedIntervals);
}

void FrameAssembler::pushDatagram(std::span<const uint8_t> datagram, Clock::time_point now,
                                  const FrameHandler& onFrame) {
  auto packet = parseMjpegPacket(datagram);
  if (!packet) {
    ++stats_.packets;
    if (packet.error() == PacketError::Keepalive)
      ++stats_.keepalives;
    else
      ++stats_.packetsInvalid;
    return;
  }
  pushPacket(*packet, now, onFrame);
}

void FrameAssembler::pushPacket(const MjpegPacket& packet, Clock::time_point now,
                                const FrameHandler& onFrame) {
  ++stats_.packets;
  stats_.payloadBytes += packet.payload.size();
  expire(now, onFrame);

  const auto& header = packet.header;
  if (packet.payload.empty() && !header.lastPacket()) {
    ++stats_.packetsEmpty;
    return;
  }
  uint64_t end = uint64_t{header.offset} + packet.payload.size();

  Slot* slot = findSlot(header.frameNumber);
  if (!slot) {
    if (lastResolved_ && !isNewer(header.frameNumber, *lastResolved_)) {
      if (*lastResolved_ - header.frameNumber <= config_.lateWindow) {
        ++stats_.packetsLate;
        return;
      }
      ++stats_.senderRestarts;
      for (auto& open : slots_)
        if (open.active) drop(open, stats_.framesAbandoned);
      lastResolved_.reset();
      lastEmitted_.reset();
    }
    if (end > config_.maxFrameBytes) {
      ++stats_.framesOversize;
      markResolved(header.frameNumber);
      discontPending_ = true;
      return;
    }
    slot = openSlot(header.frameNumber, now);
    if (!slot) {
      ++stats_.packetsLate;
      return;
    }
  }

  if (end > config_.maxFrameBytes) {
    drop(*slot, stats_.framesOversize);
    flush(onFrame);
    return;
  }
  auto frameEnd = static_cast<uint32_t>(end);
  if (header.lastPacket()) {
    bool dataBeyondEnd = !slot->received.empty() && slot->received.back().end > frameEnd;
    if ((slot->totalSize && *slot->totalSize != frameEnd) || dataBeyondEnd) {
      drop(*slot, stats_.framesLastFlagConflict);
      flush(onFrame);
      return;
    }
    slot->totalSize = frameEnd;
  } else if (slot->totalSize && frameEnd > *slot->totalSize) {
    drop(*slot, stats_.framesLastFlagConflict);
    flush(onFrame);
    return;
  }

  if (!packet.payload.empty()) {
    switch (addFragment(*slot, header.offset, packet.payload)) {
      case FragmentResult::Added:
        break;
      case FragmentResult::Duplicate:
        ++stats_.packetsDuplicate;
        return;
      case FragmentResult::Mismatch:
        drop(*slot, stats_.framesOverlapMismatch);
        flush(onFrame);
        return;
    }
  }

  // A frame held back for an older one is already complete and stays so.
  if (!slot->complete && isComplete(*slot)) {
    slot->buffer.setSize(*slot->totalSize);
    if (!startsWithJpegSoi(slot->buffer)) {
      drop(*slot, stats_.framesNotJpeg);
    } else {
      slot->complete = true;
    }
  }
  flush(onFrame);
}

FrameAssembler::FragmentResult FrameAssembler::addFragment(Slot& slot, uint32_t offset,
                                                           std::span<const uint8_t> payload) {
  auto begin = offset;
  auto end = static_cast<uint32_t>(offset + payload.size());
  auto& buffer = slot.buffer;
  if (end > buffer.capacity()) {
    size_t doubled = std::min(buffer.capacity() * 2, config_.maxFrameBytes);
    buffer.reserve(std::max<size_t>(end, doubled));
  }

  // Bytes received twice must agree, or the frame cannot be trusted.
  bool alreadyHad = false;
  for (const auto& have : slot.received) {
    if (have.begin >= end) break;
    if (have.end <= begin) continue;
    uint32_t from = std::max(begin, have.begin);
    uint32_t to = std::min(end, have.end);
    if (std::memcmp(buffer.data() + from, payload.data() + (from - begin), to - from) != 0)
      return FragmentResult::Mismatch;
    alreadyHad = alreadyHad || (have.begin <= begin && end <= have.end);
  }
  if (alreadyHad) return FragmentResult::Duplicate;

  std::memcpy(buffer.data() + begin, payload.data(), payload.size());
  buffer.setSize(std::max<size_t>(buffer.size(), end));

  auto& received = slot.received;
  auto first = std::find_if(received.begin(), received.end(),
                            [&](const Interval& have) { return have.end >= begin; });
  auto last = first;
  while (last != received.end() && last->begin <= end) {
    begin = std::min(begin, last->begin);
    end = std::max(end, last->end);
    ++last;
  }
  if (first == last) {
    received.insert(first, Interval{begin, end});
  } else {
    *first = Interval{begin, end};
    received.erase(first + 1, last);
  }
  return FragmentResult::Added;
}

bool FrameAssembler::isComplete(const Slot& slot) const {
  if (!slot.totalSize) return false;
  if (*slot.totalSize == 0) return true;  // empty: caught by the SOI check
  return slot.received.size() == 1 && slot.received[0].begin == 0 &&
         slot.received[0].end == *slot.totalSize;
}

FrameAssembler::Slot* FrameAssembler::findSlot(uint32_t number) {
  for (auto& slot : slots_)
    if (slot.active && slot.number == number) return &slot;
  return nullptr;
}

FrameAssembler::Slot* FrameAssembler::oldestActive() {
  Slot* oldest = nullptr;
  for (auto& slot : slots_)
    if (slot.active && (!oldest || isNewer(oldest->number, slot.number))) oldest = &slot;
  return oldest;
}

FrameAssembler::Slot* FrameAssembler::newestComplete() {
  Slot* newest = nullptr;
  for (auto& slot : slots_)
    if (slot.active && slot.complete && (!newest || isNewer(slot.number, newest->number)))
      newest = &slot;
  return newest;
}

FrameAssembler::Slot* FrameAssembler::openSlot(uint32_t number, Clock::time_point now) {
  auto free = std::find_if(slots_.begin(), slots_.end(), [](const Slot& s) { return !s.active; });
  Slot* slot = free != slots_.end() ? &*free : nullptr;
  if (!slot) {
    // Full: the oldest frame makes room, unless this one is older still.
    // After flush() the oldest frame is never complete, so nothing whole is
    // lost here.
    Slot* oldest = oldestActive();
    if (isNewer(oldest->number, number)) return nullptr;
    drop(*oldest, stats_.framesEvicted);
    slot = oldest;
  }
  if (slot->buffer.capacity() == 0 && !spareBuffers_.empty()) {
    slot->buffer = std::move(spareBuffers_.back());
    spareBuffers_.pop_back();
  }
  // A fresh buffer starts at the size of recent frames plus a margin, so a
  // caller that does not recycle still avoids regrowing (and recopying).
  if (slot->buffer.capacity() < largestRecentFrame_)
    slot->buffer.reserve(
        std::min(largestRecentFrame_ + largestRecentFrame_ / 4, config_.maxFrameBytes));
  slot->active = true;
  slot->number = number;
  slot->firstPacketTime = now;
  return slot;
}

void FrameAssembler::release(Slot& slot) {
  slot.active = false;
  slot.complete = false;
  slot.totalSize.reset();
  slot.received.clear();
  slot.buffer.setSize(0);
}

void FrameAssembler::markResolved(uint32_t number) {
  if (!lastResolved_ || isNewer(number, *lastResolved_)) lastResolved_ = number;
}

void FrameAssembler::drop(Slot& slot, uint64_t& reason) {
  ++reason;
  markResolved(slot.number);
  discontPending_ = true;
  release(slot);
}

void FrameAssembler::emit(Slot& slot, const FrameHandler& onFrame) {
  AssembledFrame frame;
  frame.number = slot.number;
  frame.data = std::move(slot.buffer);
  frame.firstPacketTime = slot.firstPacketTime;
  frame.discont = discontPending_ || !lastEmitted_ || slot.number != *lastEmitted_ + 1;

  ++stats_.framesComplete;
  // Decays slowly so one huge frame does not inflate every later buffer.
  largestRecentFrame_ = std::max(frame.data.size(), largestRecentFrame_ - largestRecentFrame_ / 64);
  discontPending_ = false;
  lastEmitted_ = slot.number;
  markResolved(slot.number);
  slot.buffer = FrameBuffer();
  release(slot);
  onFrame(std::move(frame));
}

void FrameAssembler::flush(const FrameHandler& onFrame) {
  while (Slot* oldest = oldestActive()) {
    if (oldest->complete) {
      emit(*oldest, onFrame);
      continue;
    }
    Slot* newest = newestComplete();
    if (newest && newest->number - oldest->number > config_.reorderWindow) {
      drop(*oldest, stats_.framesSuperseded);
      continue;
    }
    return;
  }
}

void FrameAssembler::expire(Clock::time_point now, const FrameHandler& onFrame) {
  bool dropped = false;
  for (auto& slot : slots_) {
    if (slot.active && !slot.complete && now - slot.firstPacketTime >= config_.frameTimeout) {
      drop(slot, stats_.framesTimedOut);
      dropped = true;
    }
  }
  if (dropped) flush(onFrame);
}

std::optional<FrameAssembler::Clock::time_point> FrameAssembler::nextDeadline() const {
  std::optional<Clock::time_point> deadline;
  for (const auto& slot : slots_) {
    if (!slot.active || slot.complete) continue;
    auto due = slot.firstPacketTime + config_.frameTimeout;
    if (!deadline || due < *deadline) deadline = due;
  }
  return deadline;
}

void FrameAssembler::recycle(FrameBuffer&& buffer) {
  // Keep no more spares than slots: enough for steady state, bounded memory.
  if (buffer.capacity() == 0 || spareBuffers_.size() >= slots_.size()) return;
  buffer.setSize(0);
  spareBuffers_.push_back(std::move(buffer));
}

void FrameAssembler::reset() {
  for (auto& slot : slots_) release(slot);
  lastResolved_.reset();
  lastEmitted_.reset();
  discontPending_ = true;
}

}  // namespace wircam::wirc
