// CommandPacer with a fake clock: when a command leaves.
#include "link/command_pacer.h"

#include <gtest/gtest.h>

namespace wircam::link {
namespace {

using std::chrono::milliseconds;
using Clock = CommandPacer::Clock;

Pulses steer(uint16_t pulse) {
  Pulses pulses = neutralPulses();
  pulses[0] = pulse;
  return pulses;
}

class CommandPacerTest : public ::testing::Test {
 protected:
  CommandPacer pacer{{.keepalive = milliseconds(100),
                      .minInterval = milliseconds(10),
                      .ttl = milliseconds(250),
                      .keepaliveEarly = milliseconds(10)}};
  Clock::time_point t0 = Clock::now();
  Clock::time_point at(int ms) { return t0 + milliseconds(ms); }
};

TEST_F(CommandPacerTest, SendsTheFailsafeFirstWhenNoCommandCameYet) {
  EXPECT_EQ(pacer.nextDeadline(at(0)), at(0));
  EXPECT_EQ(pacer.poll(at(0)), neutralPulses());
}

TEST_F(CommandPacerTest, SendsAChangedCommandAtOnce) {
  pacer.poll(at(0));
  EXPECT_EQ(pacer.offer(steer(1700), at(15)), steer(1700));
}

TEST_F(CommandPacerTest, DoesNotRepeatAnUnchangedCommandBeforeTheKeepalive) {
  pacer.offer(steer(1700), at(0));
  EXPECT_EQ(pacer.offer(steer(1700), at(30)), std::nullopt);
  EXPECT_EQ(pacer.poll(at(89)), std::nullopt);
  EXPECT_EQ(pacer.nextDeadline(at(89)), at(100));
  EXPECT_EQ(pacer.poll(at(100)), steer(1700));
}

TEST_F(CommandPacerTest, AKeepaliveMayLeaveEarlyToShareAWakeUpButNeverLate) {
  pacer.offer(steer(1700), at(0));
  EXPECT_EQ(pacer.poll(at(90)), steer(1700));
  EXPECT_EQ(pacer.nextDeadline(at(90)), at(190));
}

// The window a timer may go off in: a keepalive's opens keepaliveEarly
// before its deadline, and poll() sends anywhere in it; any other deadline
// (a change held back, the command running out) is a point.
TEST_F(CommandPacerTest, AKeepalivesWindowOpensAsEarlyAsPollWouldSendIt) {
  pacer.offer(steer(1700), at(0));
  auto keepalive = pacer.nextWindow(at(0));
  EXPECT_EQ(keepalive.earliest, at(90));
  EXPECT_EQ(keepalive.latest, at(100));
  EXPECT_EQ(pacer.poll(keepalive.earliest), steer(1700));

  EXPECT_EQ(pacer.offer(steer(1800), at(92)), steer(1800));
  EXPECT_EQ(pacer.offer(steer(1900), at(95)), std::nullopt);  // held by the rate limit
  auto change = pacer.nextWindow(at(95));
  EXPECT_EQ(change.earliest, at(102));
  EXPECT_EQ(change.latest, at(102));
}

TEST_F(CommandPacerTest, HoldsBackAChangeWithinTheRateLimitAndSendsItWhenAllowed) {
  pacer.offer(steer(1700), at(0));
  EXPECT_EQ(pacer.offer(steer(1800), at(4)), std::nullopt);
  EXPECT_EQ(pacer.nextDeadline(at(4)), at(10));
  EXPECT_EQ(pacer.poll(at(10)), steer(1800));
}

TEST_F(CommandPacerTest, AChangeRightAfterAKeepaliveStillLeavesAtOnce) {
  pacer.offer(steer(1700), at(0));
  ASSERT_EQ(pacer.poll(at(100)), steer(1700));  // keepalive
  EXPECT_EQ(pacer.offer(steer(1800), at(102)), steer(1800));
}

TEST_F(CommandPacerTest, GivesWayToTheFailsafeWhenTheCommandIsOlderThanTheTtl) {
  pacer.offer(steer(1700), at(0));
  pacer.poll(at(100));
  pacer.poll(at(200));
  EXPECT_EQ(pacer.nextDeadline(at(200)), at(250) + std::chrono::nanoseconds(1));
  EXPECT_EQ(pacer.poll(at(251)), neutralPulses());
  // And keeps the vehicle's watchdog fed with it.
  EXPECT_EQ(pacer.poll(at(351)), neutralPulses());
}

TEST_F(CommandPacerTest, NeverLeavesAGapLongerThanTheKeepaliveWhileNothingChanges) {
  pacer.offer(steer(1700), at(0));
  auto last = at(0);
  for (int ms = 1; ms < 2000; ++ms) {
    if (pacer.poll(at(ms))) {
      EXPECT_LE(at(ms) - last, milliseconds(100));
      last = at(ms);
    }
  }
}

// Turns of another thread every 66 ms (a stream at 15 fps, its follower
// renewing the same command each frame): the keepalive leaves on the turn
// before it would fall due, never later than the keepalive, and the link's
// timer (next deadline) is never due before the next turn.
TEST_F(CommandPacerTest, AKeepaliveRidesOnTheTurnBeforeItWouldFallDue) {
  pacer.offer(steer(1700), at(0));
  auto last = at(0);
  for (int ms = 66; ms < 2000; ms += 66) {
    EXPECT_LE(at(ms) - last, milliseconds(100)) << "at " << ms << " ms";
    EXPECT_EQ(pacer.offer(steer(1700), at(ms)), std::nullopt);
    if (pacer.pollAhead(at(ms), milliseconds(66))) last = at(ms);
    EXPECT_GE(pacer.nextDeadline(at(ms)), at(ms + 66)) << "the timer would wake at " << ms;
  }
  // At 30 fps every other turn: the keepalive is not sent more than it must.
  int sent = 0;
  for (int ms = 2000; ms < 3000; ms += 33) {
    pacer.offer(steer(1700), at(ms));
    sent += pacer.pollAhead(at(ms), milliseconds(33)) ? 1 : 0;
  }
  EXPECT_LE(sent, 16);
}

// A turn that says the next comes late (a slow frame rate, a stall) is
// believed for half the keepalive at most, so that turns coming faster
// than said do not send a keepalive each.
TEST_F(CommandPacerTest, ATurnIsBelievedForHalfTheKeepaliveAtMost) {
  pacer.offer(steer(1700), at(0));
  EXPECT_EQ(pacer.pollAhead(at(40), milliseconds(500)), std::nullopt);
  EXPECT_EQ(pacer.pollAhead(at(50), milliseconds(500)), steer(1700));
}

TEST_F(CommandPacerTest, ClampsEveryPulseIntoTheProtocolRange) {
  Pulses wild = neutralPulses();
  wild[0] = 0;
  wild[1] = 65535;
  auto sent = pacer.offer(wild, at(0));
  ASSERT_TRUE(sent.has_value());
  EXPECT_EQ((*sent)[0], kPulseMin);
  EXPECT_EQ((*sent)[1], kPulseMax);
}

TEST_F(CommandPacerTest, SendsAtOnceAfterARestart) {
  pacer.offer(steer(1700), at(0));
  pacer.restart();
  EXPECT_EQ(pacer.poll(at(1)), steer(1700));
}

}  // namespace
}  // namespace wircam::link
