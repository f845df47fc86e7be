// The WiRC vehicle link against the simulated device and misbehaving peers
// over loopback.
#include "wirc/transmitter_session.h"

#include <gtest/gtest.h>

#include <atomic>
#include <mutex>
#include <thread>

#include "devices/wirc/device.h"
#include "misbehaving_peers.h"
#include "raw_transmitter.h"
#include "wait_for.h"
#include "wirc/discovery.h"

namespace wircam::wirc {
namespace {

using std::chrono::milliseconds;
using testing::waitFor;

std::unique_ptr<Device> startDevice(DeviceConfig config = {}) {
  auto device = Device::start(config, nullptr);
  EXPECT_TRUE(device.has_value()) << device.error();
  return std::move(*device);
}

SessionConfig sessionFor(const Device& device, std::string name = "test") {
  return {.host = "127.0.0.1", .port = device.port(), .transmitterName = std::move(name)};
}

std::shared_ptr<TransmitterSession> acquire(const SessionConfig& config,
                                            const std::string& user = "test") {
  auto session = TransmitterSession::acquire(config, user);
  EXPECT_TRUE(session.has_value()) << session.error();
  return session ? *session : nullptr;
}

// Every event a link emits, for assertions.
class EventLog {
 public:
  explicit EventLog(TransmitterSession& session) : session_(session) {
    id_ = session.addListener([this](const link::LinkEvent& event) {
      std::lock_guard lock(mutex_);
      events_.push_back(event);
    });
  }
  ~EventLog() { session_.removeListener(id_); }

  template <typename T>
  std::optional<T> first() {
    std::lock_guard lock(mutex_);
    for (const auto& event : events_)
      if (const auto* found = std::get_if<T>(&event)) return *found;
    return std::nullopt;
  }
  template <typename T>
  std::optional<T> last() {
    std::lock_guard lock(mutex_);
    for (auto event = events_.rbegin(); event != events_.rend(); ++event)
      if (const auto* found = std::get_if<T>(&*event)) return *found;
    return std::nullopt;
  }

 private:
  TransmitterSession& session_;
  int id_;
  std::mutex mutex_;
  std::vector<link::LinkEvent> events_;
};

TEST(TransmitterSession, LogsInAndTakesTheControlRight) {
  auto device = startDevice({.port = 0, .cameras = 2});
  auto session = acquire(sessionFor(*device));
  ASSERT_EQ(session->waitLoggedIn(milliseconds(3000)), std::nullopt);
  EXPECT_EQ(session->sessionStatus().cameraCount, 2);
  EXPECT_TRUE(waitFor([&] { return session->status().hasControl; }));
}

TEST(TransmitterSession, IsSharedByEveryUserOfTheSameDevice) {
  auto device = startDevice({.port = 0});
  auto a = acquire(sessionFor(*device), "a");
  auto b = acquire(sessionFor(*device), "b");
  EXPECT_EQ(a.get(), b.get());
  ASSERT_EQ(a->waitLoggedIn(milliseconds(3000)), std::nullopt);
  // The device publishes its counters just after it answers.
  EXPECT_TRUE(waitFor([&] { return device->stats().logins > 0; }));
  EXPECT_EQ(device->stats().logins, 1u);
}

TEST(TransmitterSession, RefusesASettingAnotherUserGaveDifferentlyNamingBoth) {
  auto device = startDevice({.port = 0});
  auto config = sessionFor(*device, "alice");
  config.given = {"transmitter-name"};
  auto first = acquire(config, "wircsrc0");
  config.transmitterName = "bob";
  auto second = TransmitterSession::acquire(config, "wirccontrol0");
  ASSERT_FALSE(second.has_value());
  for (const char* part : {"transmitter-name", "'alice'", "'bob'", "wircsrc0", "wirccontrol0"})
    EXPECT_NE(second.error().find(part), std::string::npos) << second.error();
}

TEST(TransmitterSession, AdoptsASettingNobodyGaveAndLogsInAgainWithIt) {
  auto device = startDevice({.port = 0});
  // The first user (like wirccontrol, a sink, starting first) names no login
  // settings; the second (like wircsrc) does.
  auto first = acquire(sessionFor(*device, "wircam"), "wirccontrol0");
  ASSERT_EQ(first->waitLoggedIn(milliseconds(3000)), std::nullopt);
  auto config = sessionFor(*device, "alice");
  config.priority = 7;
  config.given = {"transmitter-name", "priority"};
  auto second = acquire(config, "wircsrc0");
  ASSERT_EQ(first.get(), second.get());
  EXPECT_TRUE(waitFor([&] { return second->status().logins == 2; }));
  auto list = second->listTransmitters(milliseconds(2000));
  ASSERT_TRUE(list.has_value());
  ASSERT_EQ(list->size(), 1u);  // the first login was replaced, not doubled
  EXPECT_EQ((*list)[0].name, "alice");
  EXPECT_EQ((*list)[0].priority, 7);
}

TEST(TransmitterSession, RefusesANameTheProtocolCannotCarry) {
  auto result = TransmitterSession::acquire({.host = "127.0.0.1", .transmitterName = "Pál"});
  ASSERT_FALSE(result.has_value());
  EXPECT_NE(result.error().find("transmitter-name"), std::string::npos) << result.error();
}

TEST(TransmitterSession, RefusesAKeepaliveTheDeviceWatchdogWouldMiss) {
  auto result = TransmitterSession::acquire({.host = "127.0.0.1", .keepalive = milliseconds(900)});
  ASSERT_FALSE(result.has_value());
  EXPECT_NE(result.error().find("keepalive"), std::string::npos) << result.error();
}

TEST(TransmitterSession, ReportsARefusedConnection) {
  auto session = acquire({.host = "127.0.0.1", .port = testing::deadPort(), .reconnect = false});
  auto error = session->waitLoggedIn(milliseconds(3000));
  ASSERT_TRUE(error.has_value());
  EXPECT_NE(error->find("cannot connect"), std::string::npos) << *error;
  EXPECT_EQ(session->status().state, link::LinkState::Failed);
}

TEST(TransmitterSession, GivesUpOnAPeerThatAcceptsButNeverAnswers) {
  testing::SilentPeer peer;
  auto session = acquire({.host = "127.0.0.1",
                          .port = peer.port(),
                          .loginTimeout = milliseconds(300),
                          .reconnect = false});
  auto error = session->waitLoggedIn(milliseconds(3000));
  ASSERT_TRUE(error.has_value());
  EXPECT_NE(error->find("no WST"), std::string::npos) << *error;
}

TEST(TransmitterSession, ReportsABusyDeviceAsBusyAtOnce) {
  testing::ScriptedPeer peer(
      {.chunks = {testing::bytesOf(
           Err{static_cast<uint8_t>(Command::Tl), static_cast<uint16_t>(ErrorCode::Busy)})}});
  auto session = acquire({.host = "127.0.0.1", .port = peer.port(), .reconnect = false});
  auto error = session->waitLoggedIn(milliseconds(3000));
  ASSERT_TRUE(error.has_value());
  EXPECT_NE(error->find("busy"), std::string::npos) << *error;
  EXPECT_NE(error->find("ERR 6"), std::string::npos) << *error;
}

TEST(TransmitterSession, GivesUpOnAConnectThatNeverCompletes) {
  testing::FullAcceptQueuePeer peer;
  auto session = acquire({.host = "127.0.0.1",
                          .port = peer.port(),
                          .loginTimeout = milliseconds(300),
                          .reconnect = false});
  auto error = session->waitLoggedIn(milliseconds(3000));
  ASSERT_TRUE(error.has_value());
  EXPECT_TRUE(error->find("cannot connect") != std::string::npos ||
              error->find("no WST") != std::string::npos)
      << *error;
}

TEST(TransmitterSession, ReleasingTheLastUserNeverWaitsOnTheNetwork) {
  testing::FullAcceptQueuePeer peer;
  auto session = acquire({.host = "127.0.0.1", .port = peer.port()});
  // Mid-connect: the release must cut it short rather than wait it out.
  auto before = std::chrono::steady_clock::now();
  session.reset();
  EXPECT_LT(std::chrono::steady_clock::now() - before, milliseconds(500));
}

TEST(TransmitterSession, SendsAChangedCommandAtOnceAndKeepsTheWatchdogFedWhileNoneCome) {
  auto device = startDevice({.port = 0, .pcdTimeout = milliseconds(300)});
  auto config = sessionFor(*device);
  config.commandTtl = milliseconds(200);
  auto session = acquire(config);
  ASSERT_EQ(session->waitLoggedIn(milliseconds(3000)), std::nullopt);
  ASSERT_TRUE(waitFor([&] { return session->status().hasControl; }));
  ChannelValues drive = neutralChannels();
  drive[1] = 1700;
  session->setCommand(drive);
  EXPECT_TRUE(waitFor([&] { return device->outputs().pulses[1] == 1700; }));
  // The "pipeline" stalls: no command for three device timeouts. Keepalives
  // keep the link, and the stale command gives way to neutral.
  EXPECT_TRUE(waitFor([&] { return device->outputs().pulses[1] == kPulseNeutral; }));
  auto received = device->stats().pcdReceived;
  EXPECT_TRUE(waitFor([&] { return device->stats().pcdReceived >= received + 9; }));
  EXPECT_EQ(device->stats().failsafeEntries, 0u);
  EXPECT_FALSE(device->outputs().failsafe);
  EXPECT_EQ(session->status().state, link::LinkState::Live);
}

// A stream's receive loop lends the link its turns (every 66 ms, as at
// 15 fps): the keepalives leave on them, the device's status reports (two
// a second) are read as they leave, and the link's event loop wakes for
// neither: not for its keepalive timer (ten a second), nor for the
// reports, nor for the link's timeout, which they keep pushing back, but
// once a timeout at most. When the turns stop, the timer feeds the
// device's watchdog again.
TEST(TransmitterSession, KeepalivesAndStatusReportsRideOnAStreamsTurnsAndTheEventLoopSleeps) {
  auto device = startDevice();
  link::EventLoop loop;
  auto acquired = TransmitterSession::acquire(sessionFor(*device), "test", loop);
  ASSERT_TRUE(acquired) << acquired.error();
  auto session = *acquired;
  std::atomic<int> heard = 0;
  int listener = session->addListener([&](const link::LinkEvent& event) {
    if (std::holds_alternative<link::TelemetryReceived>(event)) ++heard;
  });
  ASSERT_EQ(session->waitLoggedIn(milliseconds(3000)), std::nullopt);
  ASSERT_TRUE(waitFor([&] { return session->status().hasControl; }));
  session->shareTurn(milliseconds(66));
  uint64_t wakeUps = loop.wakeUps();
  uint64_t reports = device->stats().psdSent;
  int heardBefore = heard;
  uint64_t commands = device->stats().pcdReceived;
  // A turn this machine let come late (past the keepalive's early margin)
  // leaves the keepalive to the timer: one wake-up it may take.
  int late = 0;
  auto last = std::chrono::steady_clock::now();
  for (int turn = 0; turn < 30; ++turn) {
    std::this_thread::sleep_for(milliseconds(66));
    auto now = std::chrono::steady_clock::now();
    if (now - last > milliseconds(85)) ++late;
    last = now;
    session->shareTurn(milliseconds(66));
  }
  uint64_t woke = loop.wakeUps() - wakeUps;
  uint64_t reported = device->stats().psdSent - reports;
  // 2 s of turns: the link's timeout (its 2 s) once, and a late turn each.
  EXPECT_LE(woke, late + 1u) << woke << " wake-ups, " << reported << " status reports, " << late
                             << " late turns";
  EXPECT_GE(device->stats().pcdReceived - commands, 29u);
  // Every report sent was heard, but one on its way (one keepalive later).
  EXPECT_GE(static_cast<uint64_t>(heard - heardBefore) + 1, reported);
  EXPECT_GE(reported, 3u);
  // Without turns, the timer feeds the watchdog: keepalives go on, and the
  // device never fails safe (its 800 ms without a command).
  commands = device->stats().pcdReceived;
  EXPECT_TRUE(waitFor([&] { return device->stats().pcdReceived >= commands + 8; }));
  EXPECT_EQ(device->stats().failsafeEntries, 0u);
  // And the reports still come, with the keepalives the timer sends.
  int heardWithoutTurns = heard;
  EXPECT_TRUE(waitFor([&] { return heard >= heardWithoutTurns + 2; }));
  EXPECT_EQ(session->status().state, link::LinkState::Live);
  session->removeListener(listener);
  session.reset();  // logs out on the loop, before it goes
}

TEST(TransmitterSession, ClampsCommandsIntoThePulseRange) {
  auto device = startDevice({.port = 0});
  auto session = acquire(sessionFor(*device));
  ASSERT_EQ(session->waitLoggedIn(milliseconds(3000)), std::nullopt);
  ASSERT_TRUE(waitFor([&] { return session->status().hasControl; }));
  ChannelValues wild = neutralChannels();
  wild[0] = 5000;
  wild[1] = 10;
  session->setCommand(wild);
  EXPECT_TRUE(waitFor([&] { return device->outputs().pulses[0] == kPulseMax; }));
  EXPECT_EQ(device->outputs().pulses[1], kPulseMin);
  EXPECT_EQ(device->stats().pcdRejected, 0u);
}

TEST(TransmitterSession, ReconnectsAfterTheDeviceRestarts) {
  auto device = startDevice({.port = 0});
  uint16_t port = device->port();
  auto session = acquire(sessionFor(*device));
  ASSERT_EQ(session->waitLoggedIn(milliseconds(3000)), std::nullopt);
  device.reset();
  EXPECT_TRUE(waitFor([&] { return session->status().state == link::LinkState::Lost; }));
  device = startDevice({.port = port});
  EXPECT_TRUE(waitFor([&] { return session->status().state == link::LinkState::Live; }));
  EXPECT_EQ(session->status().logins, 2u);
}

TEST(TransmitterSession, EndsInFailedWithTheCauseWhenReconnectIsOff) {
  auto device = startDevice({.port = 0});
  auto config = sessionFor(*device);
  config.reconnect = false;
  auto session = acquire(config);
  ASSERT_EQ(session->waitLoggedIn(milliseconds(3000)), std::nullopt);
  device.reset();
  EXPECT_TRUE(waitFor([&] { return session->status().state == link::LinkState::Failed; }));
  EXPECT_NE(session->status().reason.find("closed the connection"), std::string::npos)
      << session->status().reason;
}

TEST(TransmitterSession, ReportsTheAnswerToAControlRequest) {
  auto device = startDevice({.port = 0});
  auto boss = acquire(
      {.host = "127.0.0.1", .port = device->port(), .transmitterName = "boss", .priority = 9});
  ASSERT_EQ(boss->waitLoggedIn(milliseconds(3000)), std::nullopt);
  // Same device under another name: a second transmitter of lower priority.
  auto minion = acquire(
      {.host = "localhost", .port = device->port(), .transmitterName = "minion", .priority = 1});
  ASSERT_EQ(minion->waitLoggedIn(milliseconds(3000)), std::nullopt);
  EventLog minionEvents(*minion);
  minion->requestControl();
  ASSERT_TRUE(waitFor([&] { return minionEvents.first<link::ControlRequestAnswered>(); }));
  auto answer = *minionEvents.first<link::ControlRequestAnswered>();
  EXPECT_FALSE(answer.granted);
  EXPECT_NE(answer.reason.find("boss"), std::string::npos) << answer.reason;

  // The boss hands it over: the minion hears it, and so does its status.
  boss->requestControlFor(minion->sessionStatus().connectionId);
  EXPECT_TRUE(waitFor([&] { return minion->status().hasControl; }));
  EXPECT_TRUE(waitFor([&] { return !boss->status().hasControl; }));
  // The event leaves after the status changed (outside the session's lock):
  // looked at once, it was not there yet in one run of eight suites.
  EXPECT_TRUE(waitFor([&] {
    auto change = minionEvents.last<link::ControlRightChanged>();
    return change && change->hasControl;
  }));
}

TEST(TransmitterSession, ListsTheLoggedInTransmitters) {
  auto device = startDevice({.port = 0});
  auto session = acquire(sessionFor(*device, "lister"));
  ASSERT_EQ(session->waitLoggedIn(milliseconds(3000)), std::nullopt);
  auto list = session->listTransmitters(milliseconds(2000));
  ASSERT_TRUE(list.has_value());
  ASSERT_EQ(list->size(), 1u);
  EXPECT_EQ((*list)[0].name, "lister");
}

TEST(TransmitterSession, ConfigurationErrorsComeBackAsErr) {
  auto device = startDevice({.port = 0});
  auto first = acquire(sessionFor(*device));
  ASSERT_EQ(first->waitLoggedIn(milliseconds(3000)), std::nullopt);
  EXPECT_EQ(first->sendConfiguration(Dcfg{.name = "new-name"}, milliseconds(300)), std::nullopt);
  // Another name for the same device: a second session, a second transmitter.
  auto second = acquire({.host = "localhost", .port = device->port(), .transmitterName = "second"});
  EventLog events(*second);
  ASSERT_EQ(second->waitLoggedIn(milliseconds(3000)), std::nullopt);
  auto err = second->sendConfiguration(Dcfg{.name = "stolen"}, milliseconds(1000));
  ASSERT_TRUE(err.has_value());
  EXPECT_EQ(err->code, static_cast<uint16_t>(ErrorCode::Denied));
  ASSERT_TRUE(waitFor([&] { return events.first<link::DeviceRefused>(); }));
  EXPECT_EQ(events.first<link::DeviceRefused>()->meaning, "denied");
}

TEST(TransmitterSession, FindsTheDeviceByDiscovery) {
  auto device = startDevice({.port = 0, .name = "finder"});
  auto session =
      acquire({.port = device->port(), .device = "finder", .discoveryAddress = "127.0.0.1"});
  ASSERT_EQ(session->waitLoggedIn(milliseconds(3000)), std::nullopt);
  EXPECT_EQ(session->sessionStatus().deviceName, "finder");
}

TEST(Discovery, FindsTheSimulatedDeviceByName) {
  auto device = startDevice({.port = 0, .name = "finder"});
  auto found = discoverDevices(milliseconds(300), "127.0.0.1", device->port());
  ASSERT_TRUE(found.has_value()) << found.error();
  auto picked = pickDevice(*found, "finder");
  ASSERT_TRUE(picked.has_value()) << picked.error();
  EXPECT_EQ(picked->address.port(), device->port());
  auto wrong = pickDevice(*found, "other");
  ASSERT_FALSE(wrong.has_value());
  EXPECT_NE(wrong.error().find("finder"), std::string::npos);
}

}  // namespace
}  // namespace wircam::wirc
