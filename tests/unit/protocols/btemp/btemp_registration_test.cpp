// The BTEMP controller's search and registration with a fake clock: probes
// every second, RCTR at once on a robot's PIAK and every second until RCAK,
// the keepalive timeout's loss and the search again where the robot was.
#include "btemp/btemp_registration.h"

#include <gtest/gtest.h>

namespace {

using namespace wircam;
using namespace wircam::btemp;
using std::chrono::milliseconds;
using Clock = Registration::Clock;

const SocketAddress kRobot = *SocketAddress::resolve("127.0.0.1", 16980);
const NodeInfo kSelf{Guid{1}, nodeFlags(NodeType::Controller)};
const NodeInfo kRobotNode{Guid{2}, nodeFlags(NodeType::Robot)};

template <typename T>
const T* find(const RegistrationActions& actions) {
  for (const auto& action : actions)
    if (const auto* found = std::get_if<T>(&action)) return found;
  return nullptr;
}

template <typename Event>
const Event* findEvent(const RegistrationActions& actions) {
  for (const auto& action : actions)
    if (const auto* emit = std::get_if<registration::Emit>(&action))
      if (const auto* event = std::get_if<Event>(&emit->event)) return event;
  return nullptr;
}

class RegistrationTest : public ::testing::Test {
 protected:
  RegistrationActions at(milliseconds offset, const SocketAddress& from, const Message& message) {
    return registration_.onDatagram(from, encode(message), start_ + offset);
  }
  RegistrationActions deadlineAt(milliseconds offset) {
    return registration_.onDeadline(start_ + offset);
  }
  milliseconds deadline() const {
    return std::chrono::duration_cast<milliseconds>(registration_.nextDeadline() - start_);
  }
  void registerAt(milliseconds offset) {
    deadlineAt(offset);
    at(offset, kRobot, Piak{kRobotNode});
    deadlineAt(offset);
    at(offset, kRobot, Rcak{});
  }

  Clock::time_point start_ = Clock::time_point(std::chrono::hours(1));
  Registration registration_{kSelf, "127.0.0.1", 16980, milliseconds(10000), start_};
};

TEST_F(RegistrationTest, ProbesEverySecondUntilARobotAnswersThenRegistersAtOnce) {
  EXPECT_EQ(deadline(), milliseconds(0));
  auto probe = deadlineAt(milliseconds(0));
  ASSERT_NE(find<registration::Probe>(probe), nullptr);
  EXPECT_EQ(find<registration::Probe>(probe)->host, "127.0.0.1");
  EXPECT_EQ(deadline(), milliseconds(1000));
  EXPECT_TRUE(deadlineAt(milliseconds(999)).empty());
  EXPECT_NE(find<registration::Probe>(deadlineAt(milliseconds(1000))), nullptr);

  // A controller's PIAK is not a robot's.
  EXPECT_TRUE(at(milliseconds(1200), kRobot, Piak{kSelf}).empty());
  EXPECT_EQ(registration_.phase(), Registration::Phase::Probing);
  at(milliseconds(1300), kRobot, Piak{kRobotNode});
  EXPECT_EQ(registration_.phase(), Registration::Phase::Registering);
  EXPECT_EQ(deadline(), milliseconds(1300));  // RCTR at once
  auto rctr = deadlineAt(milliseconds(1300));
  ASSERT_NE(find<registration::Send>(rctr), nullptr);
  EXPECT_TRUE(std::holds_alternative<Rctr>(find<registration::Send>(rctr)->message));
  EXPECT_EQ(find<registration::Send>(rctr)->to, kRobot);
  EXPECT_EQ(deadline(), milliseconds(2300));  // again every second until RCAK

  auto registered = at(milliseconds(1400), kRobot, Rcak{});
  ASSERT_NE(findEvent<link::StateChanged>(registered), nullptr);
  EXPECT_EQ(findEvent<link::StateChanged>(registered)->state, link::LinkState::Live);
  ASSERT_NE(findEvent<link::ControlRightChanged>(registered), nullptr);
  EXPECT_NE(find<registration::StartCommands>(registered), nullptr);
  EXPECT_EQ(registration_.registeredRobot(), kRobot);
}

TEST_F(RegistrationTest, SilenceForTheKeepaliveTimeoutLosesTheRobotAndSearchesWhereItWas) {
  registerAt(milliseconds(0));
  at(milliseconds(4000), kRobot, Idle{});  // anything from the robot keeps it
  EXPECT_EQ(deadline(), milliseconds(14000));
  EXPECT_TRUE(deadlineAt(milliseconds(13999)).empty());
  auto lost = deadlineAt(milliseconds(14000));
  ASSERT_NE(findEvent<link::StateChanged>(lost), nullptr);
  EXPECT_EQ(findEvent<link::StateChanged>(lost)->state, link::LinkState::Lost);
  EXPECT_NE(findEvent<link::StateChanged>(lost)->reason.find("for 10000 ms (keepalive timeout)"),
            std::string::npos);
  ASSERT_NE(findEvent<link::ControlRightChanged>(lost), nullptr);
  EXPECT_FALSE(findEvent<link::ControlRightChanged>(lost)->hasControl);
  EXPECT_EQ(registration_.registeredRobot(), std::nullopt);
  EXPECT_EQ(deadline(), milliseconds(14000));  // the search starts at once
  auto probe = deadlineAt(milliseconds(14000));
  ASSERT_NE(find<registration::Probe>(probe), nullptr);
  EXPECT_EQ(find<registration::Probe>(probe)->host, "127.0.0.1");
  EXPECT_EQ(find<registration::Probe>(probe)->port, 16980);
}

TEST_F(RegistrationTest, PinsArePingsAnsweredAndStrangersCounted) {
  registerAt(milliseconds(0));
  Pins pins;
  pins.inputs = 0b101;
  auto telemetry = at(milliseconds(100), kRobot, pins);
  ASSERT_NE(findEvent<link::TelemetryReceived>(telemetry), nullptr);
  EXPECT_EQ(*findEvent<link::TelemetryReceived>(telemetry)->telemetry.inputs, 0b101u);

  auto answer = at(milliseconds(200), kRobot, Ping{kRobotNode});
  ASSERT_NE(find<registration::Send>(answer), nullptr);
  EXPECT_TRUE(std::holds_alternative<Piak>(find<registration::Send>(answer)->message));
  EXPECT_TRUE(at(milliseconds(200), kRobot, Ping{NodeInfo{Guid{3}, kNoResponse}}).empty());

  auto stranger = *SocketAddress::resolve("127.0.0.1", 17000);
  EXPECT_TRUE(at(milliseconds(300), stranger, Pins{}).empty());
  EXPECT_EQ(registration_.status().foreignDatagrams, 1u);
  std::vector<uint8_t> junk(30, 0x55);
  EXPECT_TRUE(registration_.onDatagram(kRobot, junk, start_).empty());
  EXPECT_EQ(registration_.status().inputRejected, 1u);
}

}  // namespace
