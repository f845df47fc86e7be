// The RCOIP and BTEMP vehicle links over real loopback sockets: against the
// simulated receiver and robot, and against a raw UDP socket playing a
// broken or hostile vehicle byte for byte.
#include <gtest/gtest.h>
#include <poll.h>
#include <sys/socket.h>

#include <array>
#include <atomic>
#include <mutex>
#include <optional>
#include <vector>

#include "btemp/btemp_controller.h"
#include "common/socket.h"
#include "devices/btemp/btemp_robot.h"
#include "devices/rcoip/rcoip_receiver.h"
#include "held_port.h"
#include "rcoip/rcoip_transmitter.h"
#include "wait_for.h"

namespace wircam {
namespace {

using std::chrono::milliseconds;
using testing::waitFor;
using Bytes = std::vector<uint8_t>;
using Clock = std::chrono::steady_clock;

// A UDP socket on an ephemeral loopback port, playing the vehicle.
struct RawPeer {
  UniqueFd fd = std::move(*bindUdp(SocketAddress::loopback(0)));
  uint16_t port() const { return localAddress(fd.get()).port(); }
  // The next datagram within `timeout`, and who sent it.
  std::optional<std::pair<Bytes, SocketAddress>> receive(
      milliseconds timeout = milliseconds(3000)) {
    pollfd p{fd.get(), POLLIN, 0};
    if (::poll(&p, 1, static_cast<int>(timeout.count())) <= 0) return std::nullopt;
    std::array<uint8_t, 2048> buffer;
    sockaddr_in from{};
    socklen_t size = sizeof from;
    ssize_t n = ::recvfrom(fd.get(), buffer.data(), buffer.size(), 0,
                           reinterpret_cast<sockaddr*>(&from), &size);
    if (n < 0) return std::nullopt;
    return std::pair{Bytes(buffer.begin(), buffer.begin() + n), SocketAddress(from)};
  }
  void send(const SocketAddress& to, const Bytes& bytes) { sendDatagram(fd.get(), to, bytes); }
};

// Every event a link emits, for the test thread to look at.
struct Events {
  std::mutex mutex;
  std::vector<link::LinkEvent> seen;
  int id = 0;
  link::VehicleLink* link = nullptr;
  explicit Events(link::VehicleLink& l) : link(&l) {
    id = l.addListener([this](const link::LinkEvent& e) {
      std::lock_guard lock(mutex);
      seen.push_back(e);
    });
  }
  ~Events() { link->removeListener(id); }
  template <typename T>
  int count() {
    std::lock_guard lock(mutex);
    int n = 0;
    for (const auto& e : seen) n += std::holds_alternative<T>(e);
    return n;
  }
  bool sawState(link::LinkState state) {
    std::lock_guard lock(mutex);
    for (const auto& e : seen)
      if (const auto* s = std::get_if<link::StateChanged>(&e); s && s->state == state) return true;
    return false;
  }
};

// --- RCOIP ---------------------------------------------------------------

TEST(RcoipLink, SendsNeutralChannelBytesAtOnceAndAChangeWithoutWaiting) {
  RawPeer receiver;
  auto link = rcoip::Transmitter::acquire({.host = "127.0.0.1", .port = receiver.port()});
  ASSERT_TRUE(link) << link.error();
  auto first = receiver.receive();
  ASSERT_TRUE(first);
  EXPECT_EQ(first->first, (Bytes{1, 128, 128, 128, 128, 128, 128, 128, 128}));
  link::Pulses pulses = link::neutralPulses();
  pulses[0] = 2200, pulses[1] = 800, pulses[2] = 3000;  // out of range: clamped
  (*link)->setCommand(pulses);
  auto change = receiver.receive(milliseconds(200));  // the keepalive is 1 s away
  ASSERT_TRUE(change);
  EXPECT_EQ(change->first, (Bytes{1, 255, 0, 255, 128, 128, 128, 128, 128}));
}

TEST(RcoipLink, GoesLiveOnRepliesWithBatteryAndRssiAndIgnoresOthers) {
  RawPeer receiver, stranger;
  auto link = rcoip::Transmitter::acquire({.host = "127.0.0.1", .port = receiver.port()});
  ASSERT_TRUE(link);
  Events events(**link);
  auto command = receiver.receive();
  ASSERT_TRUE(command);
  SocketAddress transmitter = command->second;
  stranger.send(transmitter, {1, 9, 255});      // not the receiver: ignored
  receiver.send(transmitter, {});               // malformed: counted
  receiver.send(transmitter, {2, 200, 255});    // wrong version
  receiver.send(transmitter, {1, 1, 2, 3, 4});  // wrong length
  ASSERT_TRUE(waitFor([&] { return (*link)->status().inputRejected == 3; }));
  EXPECT_EQ((*link)->status().state, link::LinkState::Connecting);
  receiver.send(transmitter, {1, 200, 255});
  ASSERT_TRUE(waitFor([&] { return (*link)->status().state == link::LinkState::Live; }));
  auto status = (*link)->transmitterStatus();
  EXPECT_EQ(status.foreignDatagrams, 1u);
  ASSERT_TRUE(status.telemetry);
  EXPECT_DOUBLE_EQ(*status.telemetry->batteryVolts, 15.0);
  EXPECT_EQ(*status.telemetry->rssi, 200);
  receiver.send(transmitter, {1, 17});  // the 2-byte variant
  ASSERT_TRUE(waitFor([&] { return events.count<link::TelemetryReceived>() == 2; }));
  EXPECT_DOUBLE_EQ(*(*link)->status().telemetry->batteryVolts, 1.0);
}

TEST(RcoipLink, ReportsLostWhenTheReceiverGoesAwayAndLiveWhenItComesBack) {
  auto receiver = rcoip::Receiver::start({.port = 0});
  ASSERT_TRUE(receiver);
  uint16_t port = (*receiver)->port();
  auto link = rcoip::Transmitter::acquire({.host = "127.0.0.1",
                                           .port = port,
                                           .keepalive = milliseconds(200),
                                           .failInterval = milliseconds(1200)});
  ASSERT_TRUE(link);
  Events events(**link);
  ASSERT_TRUE(waitFor([&] { return (*link)->status().state == link::LinkState::Live; }));
  receiver->reset();
  testing::HeldPort off(port);
  ASSERT_TRUE(waitFor([&] { return events.sawState(link::LinkState::Lost); }, milliseconds(3000)));
  off.release();
  auto again = rcoip::Receiver::start({.port = port});
  ASSERT_TRUE(again);
  ASSERT_TRUE(waitFor([&] { return (*link)->status().state == link::LinkState::Live; },
                      milliseconds(3000)));
}

TEST(RcoipReceiver, RepliesAtMostOncePerIntervalOnlyToTheSenderAndFailsSafe) {
  auto receiver = rcoip::Receiver::start({.port = 0});
  ASSERT_TRUE(receiver);
  RawPeer transmitter;
  auto to = SocketAddress::loopback((*receiver)->port());
  for (int i = 0; i < 5; ++i) transmitter.send(to, {1, 255, 0});
  auto reply = transmitter.receive();
  ASSERT_TRUE(reply);
  EXPECT_EQ(reply->first, (Bytes{1, 200, 189}));         // 11.1 V = 188.7 → 189
  EXPECT_FALSE(transmitter.receive(milliseconds(300)));  // no second reply within the second
  ASSERT_TRUE(waitFor([&] { return (*receiver)->stats().commands == 5; }));
  auto now = Clock::now();
  auto outputs = (*receiver)->outputs(now);
  EXPECT_FALSE(outputs.failsafe);
  EXPECT_EQ(outputs.pulses[0], 2200);
  EXPECT_EQ(outputs.pulses[1], 800);
  EXPECT_EQ(outputs.pulses[2], 800);  // a channel the command left out reads 0
  // The transmitter went away: after the fail interval, neutral.
  auto later = (*receiver)->outputs(now + milliseconds(2100));
  EXPECT_TRUE(later.failsafe);
  EXPECT_EQ(later.pulses, link::neutralPulses());
  EXPECT_EQ((*receiver)->stats().failsafeEntries, 1u);
}

TEST(RcoipLink, RefusesSettingsTheReceiverCannotLiveWith) {
  EXPECT_FALSE(rcoip::Transmitter::acquire({.channelCount = 0}));
  EXPECT_FALSE(rcoip::Transmitter::acquire({.channelCount = 13}));
  EXPECT_FALSE(rcoip::Transmitter::acquire({.keepalive = milliseconds(2000)}));
  EXPECT_FALSE(rcoip::Transmitter::acquire({.failInterval = milliseconds(900)}));
}

TEST(RcoipLink, IsSharedByEveryUserWithTheSameSettingsAndRefusesOthersNamingBoth) {
  RawPeer receiver;
  auto a = rcoip::Transmitter::acquire({.host = "127.0.0.1", .port = receiver.port()}, "first");
  auto b = rcoip::Transmitter::acquire({.host = "127.0.0.1", .port = receiver.port()}, "second");
  ASSERT_TRUE(a && b);
  EXPECT_EQ(a->get(), b->get());
  auto c = rcoip::Transmitter::acquire(
      {.host = "127.0.0.1", .port = receiver.port(), .channelCount = 4}, "third");
  ASSERT_FALSE(c);
  // The same message as WiRC's: the setting, both values, both users.
  for (const char* part : {"channels=4 of third", "channels=8 of ", "conflicts with"})
    EXPECT_NE(c.error().find(part), std::string::npos) << c.error();
  // Once the others let go, the link closes and the next user opens it anew.
  a->reset();
  b->reset();
  EXPECT_TRUE(rcoip::Transmitter::acquire(
      {.host = "127.0.0.1", .port = receiver.port(), .channelCount = 4}, "third"));
}

// --- BTEMP ---------------------------------------------------------------

TEST(BtempLink, RegistersWithTheRobotAndDecodesItsPins) {
  auto robot = btemp::Robot::start({.port = 0});
  ASSERT_TRUE(robot);
  auto link = btemp::Controller::acquire({.host = "127.0.0.1", .port = (*robot)->port()});
  ASSERT_TRUE(link);
  ASSERT_TRUE(waitFor([&] { return (*link)->status().state == link::LinkState::Live; }));
  EXPECT_TRUE((*link)->status().hasControl);
  link::Pulses pulses = link::neutralPulses();
  pulses[0] = 2200, pulses[3] = 800;
  (*link)->setCommand(pulses);
  ASSERT_TRUE(waitFor([&] { return (*robot)->outputs(Clock::now()).pulses[0] == 2200; }));
  EXPECT_EQ((*robot)->outputs(Clock::now()).pulses[3], 800);
  ASSERT_TRUE(waitFor([&] {
    (*link)->setCommand(pulses);  // held, as a pipeline does, so it never runs out
    auto t = (*link)->status().telemetry;
    return t && t->pdmDuty.size() == 4 && t->pdmDuty.at(0) == 255;
  }));
  auto status = (*link)->controllerStatus();
  EXPECT_EQ(*status.telemetry->inputs, 0x1u);
  EXPECT_EQ(status.telemetry->pdmDuty.at(3), 0);
  ASSERT_TRUE(status.robot);
  EXPECT_EQ(btemp::nodeTypeOf(status.robot->flags), btemp::NodeType::Robot);
}

TEST(BtempLink, SpeaksThePingRctrCtrlSequenceAndDropsWhatIsNotTheRobots) {
  RawPeer robot, stranger;
  auto link = btemp::Controller::acquire(
      {.host = "127.0.0.1", .port = robot.port(), .ctrlPeriod = milliseconds(50)});
  ASSERT_TRUE(link);
  auto ping = robot.receive();
  ASSERT_TRUE(ping);
  auto decoded = btemp::decode(ping->first);
  ASSERT_TRUE(decoded);
  ASSERT_TRUE(std::get<btemp::Ping>(*decoded).sender);
  EXPECT_EQ(btemp::nodeTypeOf(std::get<btemp::Ping>(*decoded).sender->flags),
            btemp::NodeType::Controller);
  SocketAddress controller = ping->second;
  robot.send(controller,
             btemp::encode(btemp::Piak{{{}, btemp::nodeFlags(btemp::NodeType::Robot)}}));
  std::optional<btemp::Message> message;
  do {
    auto next = robot.receive();
    ASSERT_TRUE(next);
    message = *btemp::decode(next->first);
  } while (!std::holds_alternative<btemp::Rctr>(*message));

  Bytes badHash = btemp::encode(btemp::Rcak{});
  badHash[2] ^= 0xFF;
  robot.send(controller, badHash);                          // counted
  robot.send(controller, {0xef, 1, 2});                     // counted
  stranger.send(controller, btemp::encode(btemp::Rcak{}));  // ignored
  ASSERT_TRUE(waitFor([&] { return (*link)->status().inputRejected == 2; }));
  EXPECT_EQ((*link)->status().state, link::LinkState::Connecting);
  robot.send(controller, btemp::encode(btemp::Rcak{}));
  ASSERT_TRUE(waitFor([&] { return (*link)->status().state == link::LinkState::Live; }));
  EXPECT_EQ((*link)->controllerStatus().foreignDatagrams, 1u);

  // Nobody has commanded yet: IDLE. Then CTRL with channels 1..4 as bytes.
  auto idle = robot.receive();
  ASSERT_TRUE(idle);
  EXPECT_TRUE(std::holds_alternative<btemp::Idle>(*btemp::decode(idle->first)));
  link::Pulses pulses = link::neutralPulses();
  pulses[0] = 800, pulses[1] = 2200;
  (*link)->setCommand(pulses);
  auto ctrl = robot.receive(milliseconds(500));
  ASSERT_TRUE(ctrl);
  EXPECT_EQ(std::get<btemp::Ctrl>(*btemp::decode(ctrl->first)),
            (btemp::Ctrl{.throttle = {0, 255, 128, 128}}));
  // And again within the CTRL period, unchanged.
  auto repeat = robot.receive(milliseconds(200));
  ASSERT_TRUE(repeat);
  EXPECT_EQ(btemp::decode(repeat->first)->index(), btemp::decode(ctrl->first)->index());
  robot.send(controller, btemp::encode(btemp::VideoSegment{"VS1G"}));
  ASSERT_TRUE(waitFor([&] { return (*link)->controllerStatus().videoSegments == 1; }));
}

TEST(BtempLink, ReportsLostWhenTheRobotFallsSilentAndFindsItAgain) {
  auto robot = btemp::Robot::start({.port = 0, .pinsInterval = milliseconds(50)});
  ASSERT_TRUE(robot);
  uint16_t port = (*robot)->port();
  auto link = btemp::Controller::acquire(
      {.host = "127.0.0.1", .port = port, .keepaliveTimeout = milliseconds(500)});
  ASSERT_TRUE(link);
  Events events(**link);
  (*link)->setCommand(link::neutralPulses());  // CTRL, so the robot answers with PINS
  ASSERT_TRUE(waitFor([&] { return (*link)->status().state == link::LinkState::Live; }));
  robot->reset();
  ASSERT_TRUE(waitFor([&] { return events.sawState(link::LinkState::Lost); }, milliseconds(2000)));
  EXPECT_FALSE((*link)->status().hasControl);
  auto again = btemp::Robot::start({.port = port});
  ASSERT_TRUE(again);
  ASSERT_TRUE(waitFor([&] { return (*link)->status().state == link::LinkState::Live; },
                      milliseconds(3000)));
}

TEST(BtempRobot, ObeysOnlyItsRegisteredControllerAndFailsSafe) {
  auto robot = btemp::Robot::start({.port = 0});
  ASSERT_TRUE(robot);
  RawPeer controller, intruder;
  auto to = SocketAddress::loopback((*robot)->port());
  intruder.send(to, btemp::encode(btemp::Ctrl{.throttle = {255, 255, 255, 255}}));
  controller.send(to, btemp::encode(btemp::Rctr{}));
  auto rcak = controller.receive();
  ASSERT_TRUE(rcak);
  EXPECT_TRUE(std::holds_alternative<btemp::Rcak>(*btemp::decode(rcak->first)));
  controller.send(to, btemp::encode(btemp::Ctrl{.throttle = {0, 255, 128, 128}}));
  auto pins = controller.receive();
  ASSERT_TRUE(pins);
  EXPECT_EQ(std::get<btemp::Pins>(*btemp::decode(pins->first)).duty, (Bytes{0, 255, 128, 128}));
  auto now = Clock::now();
  EXPECT_EQ((*robot)->outputs(now).pulses[0], 800);
  EXPECT_EQ((*robot)->stats().ctrlForeign, 1u);
  EXPECT_TRUE((*robot)->outputs(now + milliseconds(1100)).failsafe);
}

}  // namespace
}  // namespace wircam
