#include "http/connection_slots.h"

#include <gtest/gtest.h>

namespace wircam::recorder {
namespace {

using namespace std::chrono_literals;
using Clock = ConnectionSlots::Clock;

const Clock::time_point kStart{};

ConnectionSlots slots(size_t maxOpen = 4, size_t maxPerAddress = 3) {
  return ConnectionSlots({.maxOpen = maxOpen, .maxPerAddress = maxPerAddress, .idleTimeout = 2s});
}

TEST(ConnectionSlots, RefusesPastTheCapAndPerAddressCap) {
  auto s = slots();
  for (int i = 0; i < 3; ++i) EXPECT_TRUE(s.admit("10.0.0.1", kStart));
  EXPECT_FALSE(s.admit("10.0.0.1", kStart)) << "a fourth from one address";
  EXPECT_TRUE(s.admit("10.0.0.2", kStart));
  EXPECT_FALSE(s.admit("10.0.0.3", kStart)) << "a fifth in all";
  EXPECT_EQ(s.open(), 4u);
  EXPECT_EQ(s.refused(), 2u);
}

TEST(ConnectionSlots, EveryWayOutGivesTheSlotBack) {
  auto s = slots();
  std::vector<ConnectionSlots::Id> ids;
  for (int i = 0; i < 3; ++i) ids.push_back(*s.admit("a", kStart));
  s.requestStarted(ids[1]);
  s.upgraded(ids[2]);
  for (auto id : ids) s.closed(id);
  EXPECT_EQ(s.open(), 0u);
  EXPECT_EQ(s.openFrom("a"), 0u);
  EXPECT_TRUE(s.admit("a", kStart));
  s.closed(12345);  // unknown: nothing happens
}

TEST(ConnectionSlots, ASilentConnectionExpiresAtTheIdleTimeoutOnce) {
  auto s = slots();
  auto id = *s.admit("a", kStart);
  EXPECT_TRUE(s.expired(kStart + 1999ms).empty());
  EXPECT_EQ(s.expired(kStart + 2s), std::vector<ConnectionSlots::Id>{id});
  EXPECT_TRUE(s.expired(kStart + 3s).empty()) << "named once: it is closing";
  EXPECT_EQ(s.open(), 1u) << "until it is closed";
}

TEST(ConnectionSlots, ARequestInProgressIsNeverIdle) {
  auto s = slots();
  auto id = *s.admit("a", kStart);
  s.requestStarted(id);
  EXPECT_TRUE(s.expired(kStart + 1h).empty());
  s.requestEnded(id, kStart + 1h);
  EXPECT_TRUE(s.expired(kStart + 1h + 1s).empty()) << "idle counts from the end";
  EXPECT_FALSE(s.expired(kStart + 1h + 2s).empty());
}

TEST(ConnectionSlots, AHalfOpenRequestIsIdleHoweverSlowlyItSends) {
  // Headers never completed: requestStarted() is never called.
  auto s = slots();
  auto id = *s.admit("a", kStart);
  EXPECT_EQ(s.expired(kStart + 2s), std::vector<ConnectionSlots::Id>{id});
}

TEST(ConnectionSlots, AWebSocketStaysOpenAfterItsHandshakeEnds) {
  auto s = slots();
  auto id = *s.admit("a", kStart);
  s.requestStarted(id);
  s.upgraded(id);
  s.requestEnded(id, kStart + 1s);
  EXPECT_TRUE(s.expired(kStart + 1h).empty());
}

}  // namespace
}  // namespace wircam::recorder
