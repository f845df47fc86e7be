// wirc-sim's device against raw sockets on loopback: every rule of the WiRC
// protocol the simulator promises, checked without any GStreamer.
#include "devices/wirc/device.h"

#include <gtest/gtest.h>

#include <condition_variable>
#include <mutex>
#include <thread>

#include "follow_scene.h"
#include "jpeg_sequence_scene.h"
#include "raw_transmitter.h"
#include "scene_frames.h"
#include "wait_for.h"
#include "wirc/frame_assembler.h"

namespace wircam::wirc {
namespace {

using std::chrono::milliseconds;
using testing::RawTransmitter;
using testing::receiveDatagram;
using testing::sceneFrames;

std::unique_ptr<Device> startDevice(DeviceConfig config = {},
                                    std::shared_ptr<DeviceScene> scene = nullptr) {
  config.port = 0;  // ephemeral: tests run in parallel
  auto device = Device::start(config, std::move(scene));
  EXPECT_TRUE(device.has_value()) << device.error();
  return device.has_value() ? std::move(*device) : nullptr;
}

ChannelValues pulses(uint16_t steering, uint16_t throttle) {
  ChannelValues values = neutralChannels();
  values[0] = steering;
  values[1] = throttle;
  return values;
}

void sendPcd(const Device& device, int socket, const ChannelValues& values) {
  sendDatagram(socket, SocketAddress::loopback(device.controlPort()), *encode(Pcd{values}));
}

// Keeps the controller's PCD flowing (every 50 ms) so that tests longer than
// the PCD timeout keep their connections.
class PcdPump {
 public:
  explicit PcdPump(const Device& device)
      : socket_(std::move(*bindUdp(SocketAddress::loopback(0)))),
        thread_([this, &device](std::stop_token stop) {
          while (!stop.stop_requested()) {
            sendPcd(device, socket_.get(), neutralChannels());
            ++sent;
            std::this_thread::sleep_for(milliseconds(50));
          }
        }) {}

  std::atomic<uint64_t> sent{0};

 private:
  UniqueFd socket_;
  std::jthread thread_;
};

TEST(Device, AnswersDiscoveryWithItsNameSerialAndVersions) {
  auto device = startDevice({.name = "rover-7", .serial = "AB12345", .hardware = {2, 1}});
  auto udp = bindUdp(SocketAddress::loopback(0));
  sendDatagram(udp->get(), SocketAddress::loopback(device->port()),
               *encode(Bcsd{.system = 0, .version = {1, 0}}));
  auto reply = decode(receiveDatagram(udp->get(), milliseconds(2000)));
  ASSERT_TRUE(reply.has_value());
  auto bcsa = std::get<Bcsa>(*reply);
  EXPECT_EQ(bcsa.name, "rover-7");
  EXPECT_EQ(bcsa.serial, "AB12345");
  EXPECT_EQ(bcsa.hardware, (Version{2, 1}));
}

TEST(Device, LoginEndsWithWstAndGivesTheFirstTransmitterControl) {
  auto device = startDevice({.cameras = 2});
  RawTransmitter tx(device->port());
  auto wst = tx.login("phone", 5);
  ASSERT_TRUE(wst.has_value());
  EXPECT_EQ(wst->cameraCount, 2);
  EXPECT_EQ(wst->controlPort, device->controlPort());
  auto agr = tx.receiveAs<Agr>();
  ASSERT_TRUE(agr.has_value());
  EXPECT_EQ(agr->notification, AccessNotification::Granted);
  EXPECT_EQ(agr->connectionId, wst->connectionId);
  EXPECT_EQ(agr->name, "phone");
}

TEST(Device, RefusesCommandsBeforeLogin) {
  auto device = startDevice();
  RawTransmitter tx(device->port());
  tx.send(Stst{.camera = 0, .port = 5000});
  auto err = tx.receiveAs<Err>();
  ASSERT_TRUE(err.has_value());
  EXPECT_EQ(err->command, 0x41);
  EXPECT_EQ(err->code, static_cast<uint16_t>(ErrorCode::Unauthorised));
}

TEST(Device, AnswersInvalidValuesWithErrNamingTheCommand) {
  auto device = startDevice();
  RawTransmitter tx(device->port());
  tx.send(Tl{.priority = 1, .name = "a", .statusPort = tx.statusPort()});
  Bytes badPeriods(24, 0);  // 0 µs periods: framed correctly, invalid values
  tx.sendRaw(frameRaw(0x13, badPeriods));
  auto err = tx.receiveAs<Err>();
  ASSERT_TRUE(err.has_value());
  EXPECT_EQ(err->command, 0x13);
  EXPECT_EQ(err->code, static_cast<uint16_t>(ErrorCode::Format));

  tx.sendRaw(frameRaw(0x66, Bytes{1, 2}));  // unknown command
  err = tx.receiveAs<Err>();
  ASSERT_TRUE(err.has_value());
  EXPECT_EQ(err->command, 0x66);
}

TEST(Device, OnlyTheFirstTransmitterConfiguresButOthersLogIn) {
  auto device = startDevice();
  RawTransmitter first(device->port());
  ASSERT_TRUE(first.login("first", 1).has_value());
  RawTransmitter second(device->port());
  second.send(Tl{.priority = 1, .name = "second", .statusPort = second.statusPort()});
  ChannelValues periods{};
  periods.fill(10000);
  second.send(Ccfg{periods});
  auto err = second.receiveAs<Err>();
  ASSERT_TRUE(err.has_value());
  EXPECT_EQ(err->command, 0x13);
  EXPECT_EQ(err->code, static_cast<uint16_t>(ErrorCode::Denied));
  second.send(Fcfg{neutralChannels()});
  EXPECT_TRUE(second.receiveAs<Err>().has_value());
  EXPECT_TRUE(second.receiveAs<Wst>().has_value());
  second.send(Dcfg{.name = "stolen"});
  EXPECT_EQ(second.receiveAs<Err>()->code, static_cast<uint16_t>(ErrorCode::Denied));
}

TEST(Device, ListsEveryLoggedInTransmitter) {
  auto device = startDevice();
  RawTransmitter a(device->port()), b(device->port());
  ASSERT_TRUE(a.login("alpha", 3).has_value());
  ASSERT_TRUE(b.login("beta", 7).has_value());
  b.send(Tlr{});
  std::vector<std::string> names;
  while (auto message = b.receive()) {
    if (auto* tlst = std::get_if<Tlst>(&*message)) names.push_back(tlst->name);
    if (std::holds_alternative<Tlend>(*message)) break;
  }
  EXPECT_EQ(names, (std::vector<std::string>{"alpha", "beta"}));
}

TEST(Device, AccessRequestsFollowPriority) {
  auto device = startDevice();
  RawTransmitter low(device->port()), high(device->port()), other(device->port());
  auto lowId = low.login("low", 1)->connectionId;
  ASSERT_TRUE(high.login("high", 9).has_value());
  auto otherId = other.login("other", 1)->connectionId;
  ASSERT_EQ(low.receiveAs<Agr>()->notification, AccessNotification::Granted);
  PcdPump pump(*device);

  // Not the highest priority: denied, control stays.
  other.send(Areq{otherId});
  std::optional<Agr> denied;
  while (auto m = other.receive()) {
    if (auto* agr = std::get_if<Agr>(&*m); agr && agr->notification == AccessNotification::Denied) {
      denied = *agr;
      break;
    }
  }
  ASSERT_TRUE(denied.has_value());
  EXPECT_EQ(denied->connectionId, lowId);

  // The highest priority hands control to `other`.
  high.send(Areq{otherId});
  auto lastAgr = [](RawTransmitter& tx) {
    std::optional<Agr> last;
    while (auto m = tx.receive(milliseconds(300)))
      if (auto* agr = std::get_if<Agr>(&*m)) last = *agr;
    return last;
  };
  EXPECT_EQ(lastAgr(other)->notification, AccessNotification::Granted);
  EXPECT_EQ(lastAgr(low)->notification, AccessNotification::Revoked);
  auto note = lastAgr(high);
  EXPECT_EQ(note->notification, AccessNotification::Notification);
  EXPECT_EQ(note->connectionId, otherId);
}

TEST(Device, HandsControlToTheHighestPriorityWhenTheControllerLeaves) {
  auto device = startDevice();
  auto a = std::make_unique<RawTransmitter>(device->port());
  RawTransmitter b(device->port()), c(device->port());
  ASSERT_TRUE(a->login("a", 1).has_value());
  ASSERT_TRUE(b.login("b", 2).has_value());
  ASSERT_TRUE(c.login("c", 4).has_value());
  a.reset();
  std::optional<Agr> granted;
  while (auto m = c.receive(milliseconds(1000))) {
    if (auto* agr = std::get_if<Agr>(&*m); agr && agr->notification == AccessNotification::Granted)
      granted = *agr;
    if (granted) break;
  }
  ASSERT_TRUE(granted.has_value());
  EXPECT_EQ(granted->name, "c");
}

TEST(Device, PcdDrivesTheOutputsAndItsAbsenceMeansFailsafeAndDisconnect) {
  auto device = startDevice();
  RawTransmitter tx(device->port());
  ChannelValues failsafe = neutralChannels();
  failsafe[1] = 1400;               // throttle: a pulse
  failsafe[0] = kFailsafeHoldLast;  // steering: hold
  failsafe[2] = kFailsafeConstantLevel;
  ASSERT_TRUE(tx.login("driver", 1, failsafe).has_value());
  auto udp = bindUdp(SocketAddress::loopback(0));
  for (int i = 0; i < 5; ++i) {
    sendPcd(*device, udp->get(), pulses(1700, 1650));
    std::this_thread::sleep_for(milliseconds(20));
  }
  std::this_thread::sleep_for(milliseconds(50));
  EXPECT_FALSE(device->outputs().failsafe);
  EXPECT_EQ(device->outputs().pulses[1], 1650);

  // Silence: the device must enter failsafe and drop the connection.
  while (tx.receive(milliseconds(1500))) {
  }
  EXPECT_TRUE(tx.closedByDevice());
  // The outputs are published after the close, on the device's next turn.
  EXPECT_TRUE(testing::waitFor([&] { return device->outputs().failsafe; }, milliseconds(1000)));
  auto outputs = device->outputs();
  EXPECT_EQ(outputs.pulses[0], 1700);  // held
  EXPECT_EQ(outputs.pulses[1], 1400);
  EXPECT_EQ(outputs.pulses[2], 0);
  EXPECT_EQ(device->stats().failsafeEntries, 1u);
  EXPECT_EQ(device->stats().pcdReceived, 5u);
}

// A scene that holds the device's thread once, until released, as a
// machine busy with other work keeps a simulator from its processor.
class StallingScene : public DeviceScene {
 public:
  void advance(DeviceClock::time_point, const ChannelOutputs&) override {
    std::unique_lock lock(mutex_);
    if (!stallOnce_) return;
    stallOnce_ = false;
    stalling_ = true;
    changed_.notify_all();
    changed_.wait(lock, [&] { return !stalling_; });
  }
  std::vector<uint8_t> renderJpeg(int) override { return {}; }

  void stallOnce() {
    std::lock_guard lock(mutex_);
    stallOnce_ = true;
  }
  bool stalling() {
    std::lock_guard lock(mutex_);
    return stalling_;
  }
  void release() {
    std::lock_guard lock(mutex_);
    stalling_ = false;
    changed_.notify_all();
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  bool stallOnce_ = false, stalling_ = false;
};

TEST(Device, PcdThatArrivedWhileTheDeviceWasBusyCountAtTheirArrival) {
  auto scene = std::make_shared<StallingScene>();
  auto device = startDevice({}, scene);
  RawTransmitter tx(device->port());
  ASSERT_TRUE(tx.login("driver", 1).has_value());
  PcdPump pump(*device);  // every 50 ms, from another thread
  ASSERT_TRUE(testing::waitFor([&] { return device->stats().pcdReceived >= 3; }));
  // The device's thread is held while 24 PCD (1.2 s) arrive in its socket:
  // longer than the 800 ms PCD timeout.
  scene->stallOnce();
  ASSERT_TRUE(testing::waitFor([&] { return scene->stalling(); }));
  uint64_t from = pump.sent;
  bool sentThrough = testing::waitFor([&] { return pump.sent >= from + 24; });
  scene->release();
  ASSERT_TRUE(sentThrough);
  // Once back, it reads them all before its watchdog looks.
  ASSERT_TRUE(testing::waitFor([&] { return device->stats().pcdReceived >= from + 24; }));
  EXPECT_EQ(device->stats().failsafeEntries, 0u);
  EXPECT_LT(device->stats().maxPcdGap, milliseconds(400));
  EXPECT_FALSE(tx.closedByDevice());
}

TEST(Device, IgnoresPcdOutOfRangeOrFromNoController) {
  auto device = startDevice();
  auto udp = bindUdp(SocketAddress::loopback(0));
  sendPcd(*device, udp->get(), pulses(1500, 1600));  // nobody logged in
  RawTransmitter tx(device->port());
  ASSERT_TRUE(tx.login("driver", 1).has_value());
  Bytes body(24, 0);  // every channel 0 µs
  sendDatagram(udp->get(), SocketAddress::loopback(device->controlPort()), frameRaw(0x21, body));
  EXPECT_TRUE(testing::waitFor([&] { return device->stats().pcdRejected == 2; }));
  EXPECT_EQ(device->stats().pcdReceived, 0u);
}

TEST(Device, SendsStatusEveryHalfSecond) {
  auto device = startDevice();
  RawTransmitter tx(device->port());
  ASSERT_TRUE(tx.login("watcher", 1).has_value());
  PcdPump pump(*device);
  std::vector<std::chrono::steady_clock::time_point> arrivals;
  while (arrivals.size() < 3) {
    auto datagram = receiveDatagram(tx.statusSocket(), milliseconds(1500));
    ASSERT_FALSE(datagram.empty());
    auto psd = decode(datagram);
    ASSERT_TRUE(psd.has_value());
    EXPECT_GT(std::get<Psd>(*psd).batteryMillivolts, 6000);
    arrivals.push_back(std::chrono::steady_clock::now());
  }
  auto period = std::chrono::duration_cast<milliseconds>(arrivals[2] - arrivals[0]) / 2;
  EXPECT_NEAR(period.count(), 500, 150);
}

// Receives the stream for a while and reassembles it.
struct Received {
  std::vector<std::vector<uint8_t>> frames;
  std::vector<uint32_t> numbers;
  AssemblerStats stats;
  uint64_t foreignDatagrams = 0;
};

Received receiveStream(int socket, const SocketAddress& device, milliseconds duration,
                       FrameAssemblerConfig config = {}) {
  FrameAssembler assembler(config);
  Received got;
  std::optional<uint16_t> senderPort;
  auto end = std::chrono::steady_clock::now() + duration;
  while (std::chrono::steady_clock::now() < end) {
    SocketAddress from;
    auto datagram = receiveDatagram(socket, milliseconds(50), &from);
    auto now = FrameAssembler::Clock::now();
    if (datagram.empty()) {
      assembler.expire(now, [&](AssembledFrame&&) {});
      continue;
    }
    // Only the device's stream port may feed the assembler, as wircsrc does.
    if (!senderPort) senderPort = from.port();
    if (!from.sameHost(device) || from.port() != *senderPort) {
      ++got.foreignDatagrams;
      continue;
    }
    assembler.pushDatagram(datagram, now, [&](AssembledFrame&& frame) {
      got.frames.emplace_back(frame.data.bytes().begin(), frame.data.bytes().end());
      got.numbers.push_back(frame.number);
    });
  }
  got.stats = assembler.stats();
  return got;
}

bool isSentFrame(const std::vector<uint8_t>& frame) { return testing::isSceneFrame(frame); }

struct StreamFixture {
  std::unique_ptr<Device> device;
  std::unique_ptr<RawTransmitter> tx;
  UniqueFd video;

  explicit StreamFixture(DeviceConfig config, int camera = 0) {
    config.fps = 30;
    device = startDevice(config, std::make_shared<sim::JpegSequenceScene>(sceneFrames()));
    tx = std::make_unique<RawTransmitter>(device->port());
    EXPECT_TRUE(tx->login("viewer", 1).has_value());
    video = std::move(*bindUdp(SocketAddress::loopback(0)));
    int size = 8 << 20;
    setsockopt(video.get(), SOL_SOCKET, SO_RCVBUF, &size, sizeof size);
    tx->send(
        Stst{.camera = static_cast<uint8_t>(camera), .port = localAddress(video.get()).port()});
  }
  Received receive(milliseconds duration, FrameAssemblerConfig config = {}) {
    return receiveStream(video.get(), SocketAddress::loopback(0), duration, config);
  }
};

TEST(DeviceStream, DeliversEveryFrameByteForByteAndStopsOnEst) {
  StreamFixture s({.fragmentSize = 1400});
  auto got = s.receive(milliseconds(700));
  ASSERT_GE(got.frames.size(), 10u);
  for (size_t i = 0; i < got.frames.size(); ++i) {
    EXPECT_TRUE(isSentFrame(got.frames[i])) << i;
    // The folder's order, looping.
    EXPECT_EQ(got.frames[i], sceneFrames()[(got.numbers[i]) % sceneFrames().size()]);
  }
  EXPECT_EQ(got.stats.framesDropped(), 0u);

  s.tx->send(Est{.camera = 0});
  ASSERT_TRUE(testing::waitFor([&] { return s.device->stats().activeStreams == 0; }));
  while (!receiveDatagram(s.video.get(), milliseconds(10)).empty()) {
  }
  EXPECT_TRUE(receiveDatagram(s.video.get(), milliseconds(300)).empty());
}

TEST(DeviceStream, RefusesACameraItDoesNotHave) {
  auto device = startDevice({.cameras = 2});
  RawTransmitter tx(device->port());
  ASSERT_TRUE(tx.login("viewer", 1).has_value());
  tx.send(Stst{.camera = 2, .port = 5000});
  std::optional<Err> err;
  while (auto m = tx.receive())
    if (auto* e = std::get_if<Err>(&*m)) {
      err = *e;
      break;
    }
  ASSERT_TRUE(err.has_value());
  EXPECT_EQ(err->command, 0x41);
}

TEST(DeviceStream, LossDropsFramesButNeverCorruptsOne) {
  StreamFixture s({.fragmentSize = 1400, .impairments = {.loss = 0.05, .seed = 7}});
  auto got = s.receive(milliseconds(1000));
  ASSERT_FALSE(got.frames.empty());
  for (const auto& frame : got.frames) EXPECT_TRUE(isSentFrame(frame));
  EXPECT_GT(got.stats.framesDropped(), 0u);
}

TEST(DeviceStream, BurstLossDuplicationReorderingAndJitterAreSurvived) {
  StreamFixture s({.fragmentSize = 1000,
                   .impairments = {.burstLoss = 0.01,
                                   .burstLength = 4,
                                   .duplication = 0.1,
                                   .reorderDepth = 3,
                                   .fragmentJitter = 400,
                                   .seed = 3}});
  auto got = s.receive(milliseconds(1000), {.reorderWindow = 1});
  ASSERT_GE(got.frames.size(), 5u);
  for (const auto& frame : got.frames) EXPECT_TRUE(isSentFrame(frame));
  EXPECT_GT(got.stats.packetsDuplicate, 0u);
}

TEST(DeviceStream, FrameNumbersWrapAndReservedBitsAreSet) {
  StreamFixture s({.fragmentSize = 4000,
                   .impairments = {.reservedBits = true, .startFrameNumber = 0xFFFFFFFA}});
  auto got = s.receive(milliseconds(700));
  ASSERT_GE(got.frames.size(), 10u);
  EXPECT_EQ(got.numbers.front(), 0xFFFFFFFAu);
  EXPECT_LT(got.numbers.back(), 100u);  // wrapped past 2^32
  EXPECT_EQ(got.stats.senderRestarts, 0u);
}

TEST(DeviceStream, StrayPacketsComeFromAnotherPort) {
  StreamFixture s({.fragmentSize = 64512, .impairments = {.strayRate = 0.5, .seed = 11}});
  auto got = s.receive(milliseconds(700));
  EXPECT_GT(got.foreignDatagrams, 0u);
  ASSERT_FALSE(got.frames.empty());
  for (const auto& frame : got.frames) EXPECT_TRUE(isSentFrame(frame));
}

TEST(DeviceStream, StreamsSeveralCamerasToSeveralReceivers) {
  StreamFixture s({.cameras = 2, .fragmentSize = 8000}, 1);
  auto second = bindUdp(SocketAddress::loopback(0));
  s.tx->send(Stst{.camera = 0, .port = localAddress(second->get()).port()});
  auto one = s.receive(milliseconds(500));
  auto zero = receiveStream(second->get(), SocketAddress::loopback(0), milliseconds(300));
  EXPECT_FALSE(one.frames.empty());
  EXPECT_FALSE(zero.frames.empty());
}

TEST(Device, FirmwareUpdateDisconnectsEveryoneAndRestartsWithTheNewName) {
  auto device = startDevice({.restartTime = milliseconds(300)});
  RawTransmitter a(device->port()), b(device->port());
  ASSERT_TRUE(a.login("a", 1).has_value());
  ASSERT_TRUE(b.login("b", 1).has_value());
  a.send(Dcfg{.name = "renamed"});
  a.send(Fwup{});
  while (a.receive(milliseconds(500))) {
  }
  while (b.receive(milliseconds(200))) {
  }
  EXPECT_TRUE(a.closedByDevice());
  EXPECT_TRUE(b.closedByDevice());
  ASSERT_TRUE(testing::waitFor([&] { return device->stats().restartsDone == 1; }));
  EXPECT_EQ(device->name(), "renamed");
  RawTransmitter again(device->port());
  EXPECT_TRUE(again.login("again", 1).has_value());
  EXPECT_EQ(device->stats().restarts, 1u);
}

}  // namespace
}  // namespace wircam::wirc
