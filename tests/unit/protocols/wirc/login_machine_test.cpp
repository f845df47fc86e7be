// The WiRC login machine with a fake clock: login, timeouts, backoff and its
// reset rule, link-timeout, re-login, the control right and every ERR path,
// each in microseconds of real time.
#include "wirc/login_machine.h"

#include <gtest/gtest.h>

#include <string>

namespace {

using namespace wircam;
using namespace wircam::wirc;
using std::chrono::milliseconds;
using Clock = LoginMachine::Clock;

constexpr uint16_t kStatusPort = 5000;
const SocketAddress kDevice = *SocketAddress::resolve("127.0.0.1", 1984);

template <typename T>
const T* find(const LoginActions& actions) {
  for (const auto& action : actions)
    if (const auto* found = std::get_if<T>(&action)) return found;
  return nullptr;
}

template <typename Event>
const Event* findEvent(const LoginActions& actions) {
  for (const auto& action : actions)
    if (const auto* emit = std::get_if<login::Emit>(&action))
      if (const auto* event = std::get_if<Event>(&emit->event)) return event;
  return nullptr;
}

template <typename M>
const M* findSent(const LoginActions& actions) {
  for (const auto& action : actions)
    if (const auto* send = std::get_if<login::Send>(&action))
      if (const auto* message = std::get_if<M>(&send->message)) return message;
  return nullptr;
}

class LoginMachineTest : public ::testing::Test {
 protected:
  static SessionConfig config() {
    SessionConfig c;
    c.host = "127.0.0.1";
    c.transmitterName = "tester";
    return c;
  }

  LoginActions at(milliseconds offset, auto event) {
    now_ = start_ + offset;
    return event(machine_);
  }
  // The deadline the machine named, as an offset from the start.
  milliseconds deadline() const {
    return std::chrono::duration_cast<milliseconds>(*machine_.nextDeadline() - start_);
  }
  LoginActions attemptAt(milliseconds offset) {
    return at(offset, [&](LoginMachine& m) { return m.onDeadline(now_); });
  }
  // Connects and logs in at `offset`; returns the actions of the WST.
  LoginActions loginAt(milliseconds offset) {
    attemptAt(offset);
    machine_.onConnected(now_);
    return machine_.onMessage(Wst{.connectionId = 3, .cameraCount = 2, .controlPort = 1985}, now_);
  }
  LoginActions reportAt(milliseconds offset) {
    return at(offset, [&](LoginMachine& m) { return m.onStatusReport(kDevice, Psd{}, now_); });
  }
  // The "retrying in N ms" of the StateChanged a failure emits.
  static std::string reasonOf(const LoginActions& actions) {
    const auto* changed = findEvent<link::StateChanged>(actions);
    return changed ? changed->reason : "";
  }

  Clock::time_point start_ = Clock::time_point(std::chrono::hours(1));
  Clock::time_point now_ = start_;
  LoginMachine machine_{config(), kStatusPort, start_};
};

TEST_F(LoginMachineTest, ConnectsAtOnceThenLogsInWithTlCcfgFcfgAndStartsTheStreams) {
  EXPECT_EQ(deadline(), milliseconds(0));
  EXPECT_TRUE(machine_.startStream(0, 6000).empty());  // not live yet: the login sends it
  auto connect = attemptAt(milliseconds(0));
  ASSERT_NE(find<login::Connect>(connect), nullptr);
  EXPECT_EQ(find<login::Connect>(connect)->device, kDevice);
  EXPECT_EQ(deadline(), milliseconds(3000));  // login-timeout

  auto login = machine_.onConnected(now_);
  const auto* tl = findSent<Tl>(login);
  ASSERT_NE(tl, nullptr);
  EXPECT_EQ(tl->name, "tester");
  EXPECT_EQ(tl->statusPort, kStatusPort);
  EXPECT_NE(findSent<Ccfg>(login), nullptr);
  EXPECT_NE(findSent<Fcfg>(login), nullptr);

  auto live =
      machine_.onMessage(Wst{.connectionId = 3, .cameraCount = 2, .controlPort = 1985}, now_);
  ASSERT_NE(find<login::AimCommands>(live), nullptr);
  EXPECT_EQ(find<login::AimCommands>(live)->control.port(), 1985);
  ASSERT_NE(findEvent<link::StateChanged>(live), nullptr);
  EXPECT_EQ(findEvent<link::StateChanged>(live)->state, link::LinkState::Live);
  ASSERT_NE(findSent<Stst>(live), nullptr);
  EXPECT_EQ(findSent<Stst>(live)->port, 6000);
  EXPECT_EQ(machine_.status().logins, 1u);
  EXPECT_EQ(machine_.status().cameraCount, 2);
  EXPECT_EQ(deadline(), milliseconds(2000));  // link-timeout from the login
}

TEST_F(LoginMachineTest, NoAnswerWithinTheLoginTimeoutFailsAndTheBackoffDoublesTo5s) {
  attemptAt(milliseconds(0));
  EXPECT_TRUE(attemptAt(milliseconds(2999)).empty());  // a timer that fires early does nothing
  auto failed = attemptAt(milliseconds(3000));
  EXPECT_NE(find<login::Close>(failed), nullptr);
  EXPECT_NE(reasonOf(failed).find("cannot connect to 127.0.0.1:1984 within the login timeout"),
            std::string::npos);
  EXPECT_NE(reasonOf(failed).find("retrying in 200 ms"), std::string::npos);
  EXPECT_EQ(findEvent<link::StateChanged>(failed)->state, link::LinkState::Connecting);

  milliseconds t(3000);
  for (int wait : {200, 400, 800, 1600, 3200, 5000, 5000}) {
    EXPECT_EQ(deadline(), t + milliseconds(wait));
    t += milliseconds(wait);
    ASSERT_NE(find<login::Connect>(attemptAt(t)), nullptr);  // the next attempt
    machine_.onConnected(now_);
    t += milliseconds(3000);
    EXPECT_NE(reasonOf(attemptAt(t)).find("no WST from 127.0.0.1:1984"), std::string::npos);
  }
  EXPECT_EQ(machine_.failedAttempts(), 8u);
}

TEST_F(LoginMachineTest, TheBackoffStartsOverOnlyAfterALinkThatStayedUpTenSeconds) {
  // Three quick failures: the backoff is at 1600 ms.
  milliseconds t(0);
  for (int i = 0; i < 3; ++i) {
    attemptAt(t);
    t += milliseconds(3000);
    attemptAt(t);
    t = deadline();
  }
  // Logged in for 5 s (status reports keep it up), then lost: still doubling.
  loginAt(t);
  for (int i = 1; i <= 10; ++i) reportAt(t + milliseconds(500 * i));
  t += milliseconds(5000);
  auto lost = at(t, [&](LoginMachine& m) { return m.onConnectionLost("reset", now_); });
  EXPECT_NE(reasonOf(lost).find("retrying in 1600 ms"), std::string::npos) << reasonOf(lost);
  EXPECT_EQ(findEvent<link::StateChanged>(lost)->state, link::LinkState::Lost);
  // Logged in for 10 s: the next loss waits the first backoff again.
  t = deadline();
  loginAt(t);
  for (int i = 1; i <= 20; ++i) reportAt(t + milliseconds(500 * i));
  t += milliseconds(10000);
  lost = at(t, [&](LoginMachine& m) { return m.onConnectionLost("reset", now_); });
  EXPECT_NE(reasonOf(lost).find("retrying in 200 ms"), std::string::npos) << reasonOf(lost);
}

TEST_F(LoginMachineTest, WithoutAStatusReportForTheLinkTimeoutTheDeviceIsLost) {
  loginAt(milliseconds(0));
  reportAt(milliseconds(500));
  EXPECT_EQ(deadline(), milliseconds(2500));
  EXPECT_TRUE(attemptAt(milliseconds(2499)).empty());
  auto lost = attemptAt(milliseconds(2500));
  EXPECT_NE(reasonOf(lost).find("no status report from the device for 2000 ms (link-timeout)"),
            std::string::npos)
      << reasonOf(lost);
  EXPECT_NE(find<login::Close>(lost), nullptr);
  EXPECT_EQ(machine_.status().state, link::LinkState::Lost);
}

TEST_F(LoginMachineTest, StatusReportsFromAnotherHostAreNotTheDevices) {
  loginAt(milliseconds(0));
  auto stranger = *SocketAddress::resolve("127.0.0.9", 1984);
  EXPECT_TRUE(at(milliseconds(1000), [&](LoginMachine& m) {
                return m.onStatusReport(stranger, Psd{.batteryMillivolts = 7000}, now_);
              }).empty());
  EXPECT_EQ(deadline(), milliseconds(2000));  // not kept alive by it
  auto report = at(milliseconds(1000), [&](LoginMachine& m) {
    return m.onStatusReport(kDevice, Psd{.batteryMillivolts = 7400}, now_);
  });
  ASSERT_NE(findEvent<link::TelemetryReceived>(report), nullptr);
  EXPECT_DOUBLE_EQ(*findEvent<link::TelemetryReceived>(report)->telemetry.batteryVolts, 7.4);
}

TEST_F(LoginMachineTest, WithReconnectOffALossIsTheEnd) {
  SessionConfig once = config();
  once.reconnect = false;
  LoginMachine machine(once, kStatusPort, start_);
  machine.onDeadline(start_);
  auto failed = machine.onConnectionLost("connection refused", start_);
  EXPECT_EQ(findEvent<link::StateChanged>(failed)->state, link::LinkState::Failed);
  EXPECT_EQ(reasonOf(failed), "connection refused");
  EXPECT_EQ(machine.nextDeadline(), std::nullopt);
  EXPECT_EQ(machine.phase(), LoginMachine::Phase::Closed);
}

TEST_F(LoginMachineTest, NewSettingsLogInAgainAtOnceWithoutCountingALoss) {
  loginAt(milliseconds(0));
  auto again = at(milliseconds(100), [&](LoginMachine& m) { return m.relogin("new name", now_); });
  EXPECT_NE(find<login::Close>(again), nullptr);
  EXPECT_EQ(findEvent<link::StateChanged>(again)->state, link::LinkState::Connecting);
  EXPECT_EQ(deadline(), milliseconds(100));  // at once
  EXPECT_TRUE(machine_.relogin("not connected", now_).empty());
}

TEST_F(LoginMachineTest, ARefusedLoginSaysTheDevicesMeaningAndRetries) {
  attemptAt(milliseconds(0));
  machine_.onConnected(now_);
  auto refused =
      machine_.onMessage(Err{.command = static_cast<uint8_t>(Command::Tl), .code = 2}, now_);
  ASSERT_NE(findEvent<link::DeviceRefused>(refused), nullptr);
  EXPECT_EQ(findEvent<link::DeviceRefused>(refused)->request, "TL");
  EXPECT_NE(reasonOf(refused).find("the device refused the login"), std::string::npos);
  EXPECT_NE(find<login::Close>(refused), nullptr);
  EXPECT_EQ(deadline(), milliseconds(200));
}

TEST_F(LoginMachineTest, AnErrForAnotherRequestIsReportedAndTheLinkStays) {
  loginAt(milliseconds(0));
  auto refused =
      machine_.onMessage(Err{.command = static_cast<uint8_t>(Command::Stst), .code = 1}, now_);
  ASSERT_NE(findEvent<link::DeviceRefused>(refused), nullptr);
  EXPECT_EQ(findEvent<link::DeviceRefused>(refused)->request, "STST");
  EXPECT_EQ(find<login::Close>(refused), nullptr);
  EXPECT_EQ(machine_.status().state, link::LinkState::Live);
  EXPECT_EQ(machine_.errors().size(), 1u);
}

TEST_F(LoginMachineTest, TheControlRightItsRequestsAndTheirAnswers) {
  auto early = machine_.requestControl(0);
  ASSERT_NE(findEvent<link::ControlRequestAnswered>(early), nullptr);
  EXPECT_EQ(findEvent<link::ControlRequestAnswered>(early)->reason, "not logged in");

  loginAt(milliseconds(0));
  EXPECT_NE(findSent<Areq>(machine_.requestControl(3)), nullptr);
  auto denied = machine_.onMessage(
      Agr{.connectionId = 1, .name = "boss", .notification = AccessNotification::Denied}, now_);
  ASSERT_NE(findEvent<link::ControlRequestAnswered>(denied), nullptr);
  EXPECT_FALSE(findEvent<link::ControlRequestAnswered>(denied)->granted);
  EXPECT_NE(findEvent<link::ControlRequestAnswered>(denied)->reason.find("'boss' holds it"),
            std::string::npos);

  auto granted = machine_.onMessage(Agr{.connectionId = 3, .name = "tester"}, now_);
  ASSERT_NE(findEvent<link::ControlRightChanged>(granted), nullptr);
  EXPECT_TRUE(findEvent<link::ControlRightChanged>(granted)->hasControl);
  EXPECT_NE(find<login::StartCommands>(granted), nullptr);
  EXPECT_TRUE(machine_.status().hasControl);

  // A request the device answers with ERR.
  machine_.requestControl(3);
  auto err =
      machine_.onMessage(Err{.command = static_cast<uint8_t>(Command::Areq), .code = 3}, now_);
  ASSERT_NE(findEvent<link::ControlRequestAnswered>(err), nullptr);
  EXPECT_FALSE(findEvent<link::ControlRequestAnswered>(err)->granted);

  // Lost with the link.
  auto lost = machine_.onConnectionLost("reset", now_);
  ASSERT_NE(findEvent<link::ControlRightChanged>(lost), nullptr);
  EXPECT_FALSE(findEvent<link::ControlRightChanged>(lost)->hasControl);
  EXPECT_FALSE(machine_.status().hasControl);
}

// A stranger's trial: `wirc-cli request-control 9` (no connection 9)
// said "control right given to connection 9". The AGR that gave the right
// to the CLI at its login came after the AREQ left and was taken for the
// answer; the device's denial came next and was passed over.
TEST_F(LoginMachineTest, AnAgrNamingAnotherConnectionIsNoAnswerToARequest) {
  loginAt(milliseconds(0));
  machine_.requestControl(9);
  auto ownGrant = machine_.onMessage(
      Agr{.connectionId = 1, .name = "me", .notification = AccessNotification::Granted}, now_);
  EXPECT_NE(findEvent<link::ControlRightChanged>(ownGrant), nullptr);
  EXPECT_EQ(findEvent<link::ControlRequestAnswered>(ownGrant), nullptr);
  auto denied = machine_.onMessage(
      Agr{.connectionId = 1, .name = "me", .notification = AccessNotification::Denied}, now_);
  ASSERT_NE(findEvent<link::ControlRequestAnswered>(denied), nullptr);
  EXPECT_FALSE(findEvent<link::ControlRequestAnswered>(denied)->granted);
}

TEST_F(LoginMachineTest, AGrantedRequestSaysTheRightChangedBeforeItAnswers) {
  // wirccontrol posts the answer with the right it holds then: answered
  // first, a granted request read "has-control=false, request=granted" (a
  // stranger's trial).
  loginAt(milliseconds(0));
  machine_.requestControl(3);
  auto granted = machine_.onMessage(
      Agr{.connectionId = 3, .name = "tester", .notification = AccessNotification::Granted}, now_);
  int changedAt = -1, answeredAt = -1;
  for (int i = 0; i < static_cast<int>(granted.size()); ++i)
    if (const auto* emit = std::get_if<login::Emit>(&granted[i])) {
      if (std::holds_alternative<link::ControlRightChanged>(emit->event)) changedAt = i;
      if (std::holds_alternative<link::ControlRequestAnswered>(emit->event)) answeredAt = i;
    }
  ASSERT_GE(changedAt, 0);
  ASSERT_GE(answeredAt, 0);
  EXPECT_LT(changedAt, answeredAt);
}

TEST_F(LoginMachineTest, MalformedInputIsSummedUpOnceASecondAndPastTheLimitDropsTheDevice) {
  loginAt(milliseconds(0));
  StreamParserStats stats;
  stats.badCrc = 10;
  auto first =
      at(milliseconds(1000), [&](LoginMachine& m) { return m.onParserStats(stats, now_); });
  ASSERT_NE(findEvent<link::InputRejected>(first), nullptr);
  EXPECT_EQ(findEvent<link::InputRejected>(first)->count, 10u);
  stats.badCrc = 20;
  stats.garbageBytes = 640;  // ten more, by weight
  auto quiet =
      at(milliseconds(1500), [&](LoginMachine& m) { return m.onParserStats(stats, now_); });
  EXPECT_EQ(findEvent<link::InputRejected>(quiet), nullptr);  // within the second
  stats.badCrc = 30;
  auto summed =
      at(milliseconds(2000), [&](LoginMachine& m) { return m.onParserStats(stats, now_); });
  ASSERT_NE(findEvent<link::InputRejected>(summed), nullptr);
  EXPECT_EQ(findEvent<link::InputRejected>(summed)->count, 30u);
  EXPECT_EQ(machine_.status().inputRejected, 40u);

  stats.invalidMessages = 61;  // 101 on this connection: past max-bad-messages (100)
  auto dropped =
      at(milliseconds(2100), [&](LoginMachine& m) { return m.onParserStats(stats, now_); });
  EXPECT_NE(reasonOf(dropped).find("101 malformed messages: dropped as misbehaving"),
            std::string::npos)
      << reasonOf(dropped);
  EXPECT_NE(find<login::Close>(dropped), nullptr);
}

TEST_F(LoginMachineTest, DiscoveryConnectsToTheNamedDeviceAsSoonAsItAnswers) {
  SessionConfig discover = config();
  discover.host.clear();
  discover.device = "rover";
  LoginMachine machine(discover, kStatusPort, start_);
  auto asked = machine.onDeadline(start_);
  ASSERT_NE(find<login::Discover>(asked), nullptr);
  EXPECT_EQ(find<login::Discover>(asked)->destination.toString(), "255.255.255.255:1984");
  EXPECT_EQ(*machine.nextDeadline(), start_ + milliseconds(1000));  // the discovery window

  auto other = *SocketAddress::resolve("192.168.1.7", 1984);
  EXPECT_TRUE(
      machine.onDiscoveryAnswer({other, Bcsa{.name = "car", .serial = "1"}}, start_).empty());
  auto found = machine.onDiscoveryAnswer({kDevice, Bcsa{.name = "rover", .serial = "2"}}, start_);
  EXPECT_NE(find<login::Close>(found), nullptr);  // the discovery socket
  ASSERT_NE(find<login::Connect>(found), nullptr);
  EXPECT_EQ(find<login::Connect>(found)->device, kDevice);
  EXPECT_EQ(machine.status().deviceName, "rover");
}

TEST_F(LoginMachineTest, ADiscoveryThatFindsNothingFailsAtTheEndOfItsWindow) {
  SessionConfig discover = config();
  discover.host.clear();
  LoginMachine machine(discover, kStatusPort, start_);
  machine.onDeadline(start_);
  auto failed = machine.onDeadline(start_ + milliseconds(1000));
  ASSERT_NE(findEvent<link::StateChanged>(failed), nullptr);
  EXPECT_EQ(find<login::Connect>(failed), nullptr);
  EXPECT_EQ(*machine.nextDeadline(), start_ + milliseconds(1200));
}

TEST_F(LoginMachineTest, ACameraTheDeviceLacksIsNeverAskedForSoItsRefusalBlamesNoOther) {
  // An ERR says which command failed, not which camera: a refused STST for
  // camera 5 of a two-camera device reached every camera of the link, and
  // camera 0 restarted at each of camera 5's retries (a stranger's trial).
  // The device said at login how many cameras it has (WST).
  machine_.startStream(0, 6000);
  machine_.startStream(5, 6005);
  auto live = loginAt(milliseconds(0));
  int asked = 0;
  for (const auto& action : live)
    if (const auto* send = std::get_if<login::Send>(&action))
      if (const auto* stst = std::get_if<Stst>(&send->message)) {
        EXPECT_EQ(stst->camera, 0);
        ++asked;
      }
  EXPECT_EQ(asked, 1);
  EXPECT_TRUE(machine_.startStream(7, 6007).empty());
  EXPECT_TRUE(machine_.stopStream(7).empty());
  ASSERT_NE(findSent<Stst>(machine_.startStream(1, 6001)), nullptr);
}

TEST_F(LoginMachineTest, LoggingOutStopsTheStreamsAndClosesForGood) {
  machine_.startStream(1, 6001);
  loginAt(milliseconds(0));
  auto out = machine_.close();
  ASSERT_NE(findSent<Est>(out), nullptr);
  EXPECT_EQ(findSent<Est>(out)->camera, 1);
  EXPECT_NE(find<login::Close>(out), nullptr);
  EXPECT_EQ(machine_.nextDeadline(), std::nullopt);
  EXPECT_TRUE(machine_.onConnectionLost("late", now_).empty());
}

}  // namespace
