#include "wirc/frame_assembler.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

namespace wircam::wirc {
namespace {

using Bytes = std::vector<uint8_t>;
using Clock = FrameAssembler::Clock;
using std::chrono::milliseconds;

// A frame that looks like a JPEG (SOI ... EOI) with distinct contents.
Bytes fakeJpeg(size_t size, uint32_t seed) {
  std::mt19937 random(seed);
  Bytes frame(size);
  for (auto& b : frame) b = static_cast<uint8_t>(random());
  frame[0] = 0xFF;
  frame[1] = 0xD8;
  frame[size - 2] = 0xFF;
  frame[size - 1] = 0xD9;
  return frame;
}

Bytes packet(uint32_t frame, uint32_t offset, std::span<const uint8_t> payload, bool last,
             uint32_t reservedBits = 0) {
  Bytes out;
  uint32_t version = kMjpegVersion | (last ? kLastPacketFlag : 0) | reservedBits;
  writeMjpegHeader({version, frame, offset, static_cast<uint32_t>(payload.size())}, out);
  out.insert(out.end(), payload.begin(), payload.end());
  return out;
}

class FrameAssemblerTest : public ::testing::Test {
 protected:
  void reconfigure(FrameAssemblerConfig config) { assembler_ = FrameAssembler(config); }

  void push(const Bytes& datagram, milliseconds at = milliseconds(0)) {
    assembler_.pushDatagram(datagram, start_ + at, [this](AssembledFrame&& frame) {
      numbers_.push_back(frame.number);
      disconts_.push_back(frame.discont);
      frames_.emplace_back(frame.data.bytes().begin(), frame.data.bytes().end());
      assembler_.recycle(std::move(frame.data));
    });
  }

  void pushAll(const std::vector<Bytes>& datagrams, milliseconds at = milliseconds(0)) {
    for (const auto& d : datagrams) push(d, at);
  }

  void expire(milliseconds at) {
    assembler_.expire(start_ + at, [this](AssembledFrame&& frame) {
      numbers_.push_back(frame.number);
      frames_.emplace_back(frame.data.bytes().begin(), frame.data.bytes().end());
    });
  }

  const AssemblerStats& stats() const { return assembler_.stats(); }

  Clock::time_point start_ = Clock::now();
  FrameAssembler assembler_;
  std::vector<uint32_t> numbers_;
  std::vector<bool> disconts_;
  std::vector<Bytes> frames_;
};

TEST_F(FrameAssemblerTest, AssemblesAFrameSentInOrder) {
  Bytes jpeg = fakeJpeg(5000, 1);
  pushAll(packetizeFrame(jpeg, 1, 1400));
  ASSERT_EQ(frames_.size(), 1u);
  EXPECT_EQ(frames_[0], jpeg);
  EXPECT_EQ(numbers_[0], 1u);
  EXPECT_EQ(stats().framesComplete, 1u);
  EXPECT_EQ(stats().payloadBytes, jpeg.size());
}

TEST_F(FrameAssemblerTest, AssemblesAFrameInOneDatagramAsTheDeviceSendsIt) {
  Bytes jpeg = fakeJpeg(20000, 2);
  pushAll(packetizeFrame(jpeg, 7, kDeviceFragmentSize));
  ASSERT_EQ(frames_.size(), 1u);
  EXPECT_EQ(frames_[0], jpeg);
}

TEST_F(FrameAssemblerTest, AssemblesPacketsInAnyOrder) {
  Bytes jpeg = fakeJpeg(7000, 3);
  auto packets = packetizeFrame(jpeg, 1, 500);
  std::mt19937 random(3);
  for (int trial = 0; trial < 20; ++trial) {
    std::shuffle(packets.begin(), packets.end(), random);
    reconfigure({});
    frames_.clear();
    pushAll(packets);
    ASSERT_EQ(frames_.size(), 1u) << trial;
    EXPECT_EQ(frames_[0], jpeg);
  }
}

TEST_F(FrameAssemblerTest, AssemblesWhenTheLastPacketArrivesFirst) {
  Bytes jpeg = fakeJpeg(3000, 4);
  auto packets = packetizeFrame(jpeg, 1, 1000);
  std::reverse(packets.begin(), packets.end());
  pushAll(packets);
  ASSERT_EQ(frames_.size(), 1u);
  EXPECT_EQ(frames_[0], jpeg);
}

TEST_F(FrameAssemblerTest, CountsDuplicatesAndEmitsTheFrameOnce) {
  Bytes jpeg = fakeJpeg(3000, 5);
  auto packets = packetizeFrame(jpeg, 1, 1000);
  push(packets[0]);
  push(packets[0]);
  push(packets[1]);
  push(packets[2]);
  push(packets[2]);  // after completion: late
  ASSERT_EQ(frames_.size(), 1u);
  EXPECT_EQ(frames_[0], jpeg);
  EXPECT_EQ(stats().packetsDuplicate, 1u);
  EXPECT_EQ(stats().packetsLate, 1u);
}

TEST_F(FrameAssemblerTest, AcceptsOverlappingFragmentsThatAgree) {
  Bytes jpeg = fakeJpeg(3000, 6);
  std::span<const uint8_t> all(jpeg);
  push(packet(1, 0, all.subspan(0, 1500), false));
  push(packet(1, 1000, all.subspan(1000, 1500), false));  // overlaps 1000..1500
  push(packet(1, 2000, all.subspan(2000), true));         // overlaps 2000..2500
  ASSERT_EQ(frames_.size(), 1u);
  EXPECT_EQ(frames_[0], jpeg);
  EXPECT_EQ(stats().framesOverlapMismatch, 0u);
}

TEST_F(FrameAssemblerTest, DropsAFrameWhoseOverlappingFragmentsDisagree) {
  Bytes jpeg = fakeJpeg(3000, 7);
  Bytes altered = jpeg;
  altered[1200] ^= 0xFF;
  push(packet(1, 0, std::span(jpeg).subspan(0, 1500), false));
  push(packet(1, 1000, std::span(altered).subspan(1000), true));
  EXPECT_TRUE(frames_.empty());
  EXPECT_EQ(stats().framesOverlapMismatch, 1u);
}

TEST_F(FrameAssemblerTest, DropsAFrameWhenAPacketIsMissingAfterTheTimeout) {
  reconfigure({.frameTimeout = milliseconds(100)});
  Bytes jpeg = fakeJpeg(3000, 8);
  auto packets = packetizeFrame(jpeg, 1, 1000);
  push(packets[0], milliseconds(0));
  push(packets[2], milliseconds(10));
  EXPECT_EQ(assembler_.nextDeadline(), start_ + milliseconds(100));
  expire(milliseconds(99));
  EXPECT_EQ(stats().framesTimedOut, 0u);
  expire(milliseconds(100));
  EXPECT_EQ(stats().framesTimedOut, 1u);
  push(packets[1], milliseconds(110));  // too late now
  EXPECT_TRUE(frames_.empty());
  EXPECT_EQ(stats().packetsLate, 1u);
  EXPECT_FALSE(assembler_.nextDeadline().has_value());
}

TEST_F(FrameAssemblerTest, DropsAnIncompleteFrameWhenANewerOneCompletes) {
  Bytes a = fakeJpeg(3000, 9), b = fakeJpeg(3000, 10);
  auto first = packetizeFrame(a, 1, 1000);
  push(first[0]);
  push(first[1]);  // frame 1 misses its last packet
  pushAll(packetizeFrame(b, 2, 1000));
  ASSERT_EQ(numbers_, std::vector<uint32_t>{2});
  EXPECT_EQ(frames_[0], b);
  EXPECT_EQ(stats().framesSuperseded, 1u);
  EXPECT_TRUE(disconts_[0]);
  push(first[2]);
  EXPECT_EQ(frames_.size(), 1u);
}

TEST_F(FrameAssemblerTest, ReorderWindowLetsAnOlderFrameFinishAndKeepsOrder) {
  reconfigure({.reorderWindow = 2});
  Bytes a = fakeJpeg(2000, 11), b = fakeJpeg(2000, 12);
  auto first = packetizeFrame(a, 1, 1000);
  push(first[0]);
  pushAll(packetizeFrame(b, 2, 1000));  // complete, held back for frame 1
  EXPECT_TRUE(frames_.empty());
  push(first[1]);
  ASSERT_EQ(numbers_, (std::vector<uint32_t>{1, 2}));
  EXPECT_EQ(frames_[0], a);
  EXPECT_EQ(frames_[1], b);
}

TEST_F(FrameAssemblerTest, ReorderWindowGivesUpPastTheWindow) {
  reconfigure({.reorderWindow = 1});
  Bytes a = fakeJpeg(2000, 13);
  push(packetizeFrame(a, 1, 1000)[0]);
  pushAll(packetizeFrame(fakeJpeg(2000, 14), 2, 1000));
  EXPECT_TRUE(frames_.empty());
  pushAll(packetizeFrame(fakeJpeg(2000, 15), 3, 1000));
  EXPECT_EQ(numbers_, (std::vector<uint32_t>{2, 3}));
  EXPECT_EQ(stats().framesSuperseded, 1u);
}

TEST_F(FrameAssemblerTest, HeldBackFramesAreReleasedWhenTheOlderOneTimesOut) {
  reconfigure({.frameTimeout = milliseconds(50), .reorderWindow = 5});
  push(packetizeFrame(fakeJpeg(2000, 16), 1, 1000)[0], milliseconds(0));
  pushAll(packetizeFrame(fakeJpeg(2000, 17), 2, 1000), milliseconds(10));
  EXPECT_TRUE(frames_.empty());
  expire(milliseconds(50));
  EXPECT_EQ(numbers_, std::vector<uint32_t>{2});
}

TEST_F(FrameAssemblerTest, HandlesTheFrameNumberWrappingAt2To32) {
  uint32_t number = 0xFFFFFFFE;
  for (int i = 0; i < 4; ++i, ++number) pushAll(packetizeFrame(fakeJpeg(1500, i), number, 1000));
  EXPECT_EQ(numbers_, (std::vector<uint32_t>{0xFFFFFFFE, 0xFFFFFFFF, 0, 1}));
  EXPECT_EQ(disconts_, (std::vector<bool>{true, false, false, false}));
  EXPECT_EQ(stats().senderRestarts, 0u);
}

TEST_F(FrameAssemblerTest, FollowsASenderRestartWhenFrameNumbersJumpBack) {
  for (uint32_t n = 1000; n < 1003; ++n) pushAll(packetizeFrame(fakeJpeg(1500, n), n, 1000));
  push(packetizeFrame(fakeJpeg(1500, 1), 1003, 1000)[0]);  // in flight at the restart
  for (uint32_t n = 0; n < 3; ++n) pushAll(packetizeFrame(fakeJpeg(1500, n), n, 1000));
  EXPECT_EQ(numbers_, (std::vector<uint32_t>{1000, 1001, 1002, 0, 1, 2}));
  EXPECT_EQ(stats().senderRestarts, 1u);
  EXPECT_EQ(stats().framesAbandoned, 1u);
  EXPECT_TRUE(disconts_[3]);
}

TEST_F(FrameAssemblerTest, LatePacketsJustBehindAreNotARestart) {
  for (uint32_t n = 10; n < 20; ++n) pushAll(packetizeFrame(fakeJpeg(1500, n), n, 1000));
  pushAll(packetizeFrame(fakeJpeg(1500, 5), 5, 1000));
  EXPECT_EQ(numbers_.size(), 10u);
  EXPECT_EQ(stats().packetsLate, 2u);
  EXPECT_EQ(stats().senderRestarts, 0u);
}

TEST_F(FrameAssemblerTest, CountsALengthLargerThanTheDatagramAsInvalid) {
  Bytes bad;
  writeMjpegHeader({kMjpegVersion | kLastPacketFlag, 1, 0, 100}, bad);
  bad.resize(bad.size() + 50, 0xFF);
  push(bad);
  EXPECT_EQ(stats().packetsInvalid, 1u);
  EXPECT_TRUE(frames_.empty());
}

TEST_F(FrameAssemblerTest, DropsAFrameReachingPastTheMaximumSize) {
  reconfigure({.maxFrameBytes = 3500});
  Bytes jpeg = fakeJpeg(5000, 18);
  pushAll(packetizeFrame(jpeg, 1, 1000));
  EXPECT_TRUE(frames_.empty());
  EXPECT_EQ(stats().framesOversize, 1u);
  EXPECT_EQ(stats().packetsLate, 1u);  // the fifth packet, after the fourth dropped the frame
}

TEST_F(FrameAssemblerTest, HugeOffsetsCannotOverflowOrAllocate) {
  Bytes payload = {0xFF, 0xD8};
  push(packet(1, 0xFFFFFFFF, payload, true));
  push(packet(2, 0xFFFFFFF0, payload, false));
  EXPECT_EQ(stats().framesOversize, 2u);
  EXPECT_TRUE(frames_.empty());
}

TEST_F(FrameAssemblerTest, IgnoresZeroLengthPacketsButHonoursAnEmptyLastPacket) {
  Bytes jpeg = fakeJpeg(2000, 19);
  push(packet(1, 0, std::span(jpeg), false));
  push(packet(1, 500, {}, false));
  EXPECT_EQ(stats().packetsEmpty, 1u);
  EXPECT_TRUE(frames_.empty());
  push(packet(1, 2000, {}, true));  // the end, with no bytes
  ASSERT_EQ(frames_.size(), 1u);
  EXPECT_EQ(frames_[0], jpeg);
}

TEST_F(FrameAssemblerTest, DropsAFrameWhoseLastPacketFlagsDisagree) {
  Bytes jpeg = fakeJpeg(3000, 20);
  std::span<const uint8_t> all(jpeg);
  push(packet(1, 1000, all.subspan(1000, 1000), true));  // says the end is 2000
  push(packet(1, 2000, all.subspan(2000), true));        // says the end is 3000
  EXPECT_EQ(stats().framesLastFlagConflict, 1u);
  push(packet(2, 2000, all.subspan(2000, 500), false));
  push(packet(2, 0, all.subspan(0, 1000), true));  // ends at 1000, but bytes exist up to 2500
  EXPECT_EQ(stats().framesLastFlagConflict, 2u);
  push(packet(3, 1000, all.subspan(1000, 1000), true));
  push(packet(3, 2000, all.subspan(2000, 500), false));  // beyond the flagged end
  EXPECT_EQ(stats().framesLastFlagConflict, 3u);
  EXPECT_TRUE(frames_.empty());
}

TEST_F(FrameAssemblerTest, DropsACompleteFrameThatIsNotAJpeg) {
  Bytes notJpeg(1000, 0x42);
  push(packet(1, 0, notJpeg, true));
  push(packet(2, 0, {}, true));  // an empty frame
  EXPECT_TRUE(frames_.empty());
  EXPECT_EQ(stats().framesNotJpeg, 2u);
}

TEST_F(FrameAssemblerTest, CapsTheFramesInFlightByEvictingTheOldest) {
  reconfigure({.maxFramesInFlight = 2, .reorderWindow = 100});
  Bytes jpeg = fakeJpeg(2000, 21);
  push(packet(1, 0, std::span(jpeg).first(1000), false));
  push(packet(2, 0, std::span(jpeg).first(1000), false));
  push(packet(3, 0, std::span(jpeg).first(1000), false));
  EXPECT_EQ(stats().framesEvicted, 1u);
  push(packet(1, 1000, std::span(jpeg).subspan(1000), true));  // frame 1 is gone
  EXPECT_EQ(stats().packetsLate, 1u);
  push(packet(2, 1000, std::span(jpeg).subspan(1000), true));
  EXPECT_EQ(numbers_, std::vector<uint32_t>{2});
}

TEST_F(FrameAssemblerTest, CountsKeepalivesAndBadHeadersWithoutTouchingFrames) {
  push(Bytes{0x00, 0x00, 0x55, 0x03});
  push(Bytes{0x00, 0x00, 0x55, 0x04, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0});
  push(Bytes(10, 0));
  EXPECT_EQ(stats().keepalives, 1u);
  EXPECT_EQ(stats().packetsInvalid, 2u);
  EXPECT_EQ(stats().packets, 3u);
}

TEST_F(FrameAssemblerTest, IgnoresReservedVersionBits) {
  Bytes jpeg = fakeJpeg(2000, 22);
  push(packet(1, 0, std::span(jpeg).first(1000), false, 0xABCD0000 & ~kLastPacketFlag));
  push(packet(1, 1000, std::span(jpeg).subspan(1000), true, 0xFFFE0000));
  ASSERT_EQ(frames_.size(), 1u);
  EXPECT_EQ(frames_[0], jpeg);
}

TEST_F(FrameAssemblerTest, ReusesRecycledBuffersInSteadyState) {
  Bytes jpeg = fakeJpeg(30000, 23);
  const uint8_t* firstBuffer = nullptr;
  std::vector<const uint8_t*> seen;
  for (uint32_t n = 0; n < 10; ++n) {
    for (const auto& d : packetizeFrame(jpeg, n, 1400)) {
      assembler_.pushDatagram(d, start_, [&](AssembledFrame&& frame) {
        seen.push_back(frame.data.data());
        assembler_.recycle(std::move(frame.data));
      });
    }
  }
  ASSERT_EQ(seen.size(), 10u);
  firstBuffer = seen[1];
  for (size_t i = 2; i < seen.size(); ++i) EXPECT_EQ(seen[i], firstBuffer);
}

TEST_F(FrameAssemblerTest, SurvivesLossDuplicationAndReorderingWithoutACorruptFrame) {
  reconfigure({.frameTimeout = milliseconds(100), .reorderWindow = 2});
  std::mt19937 random(99);
  std::vector<Bytes> sent;
  std::vector<Bytes> stream;
  for (uint32_t n = 0; n < 200; ++n) {
    sent.push_back(fakeJpeg(800 + random() % 6000, n));
    for (auto& d : packetizeFrame(sent.back(), n, 700)) {
      if (random() % 100 < 3) continue;             // loss
      if (random() % 100 < 3) stream.push_back(d);  // duplicate
      stream.push_back(std::move(d));
    }
  }
  for (size_t i = 0; i + 3 < stream.size(); i += 4) std::swap(stream[i], stream[i + 3]);
  for (size_t i = 0; i < stream.size(); ++i) push(stream[i], milliseconds(i));
  ASSERT_FALSE(frames_.empty());
  for (size_t i = 0; i < frames_.size(); ++i) EXPECT_EQ(frames_[i], sent[numbers_[i]]) << i;
  EXPECT_TRUE(std::is_sorted(numbers_.begin(), numbers_.end()));
  EXPECT_GT(stats().packetsDuplicate, 0u);
  EXPECT_GT(stats().framesDropped(), 0u);
}

}  // namespace
}  // namespace wircam::wirc
