// TransmitterSession against the simulated device over loopback.
#include "wirc/transmitter_session.h"

#include <gtest/gtest.h>

#include <thread>

#include "wirc/device.h"
#include "wirc/discovery.h"

namespace wircam::wirc {
namespace {

using std::chrono::milliseconds;

std::unique_ptr<Device> startDevice(DeviceConfig config = {}) {
  auto device = Device::start(config, nullptr);
  EXPECT_TRUE(device.has_value()) << device.error();
  return std::move(*device);
}

SessionConfig sessionFor(const Device& device, std::string name = "test") {
  return {.host = "127.0.0.1", .port = device.port(), .transmitterName = std::move(name)};
}

TEST(TransmitterSession, LogsInAndTakesTheControlRight) {
  auto device = startDevice({.port = 0, .cameras = 2});
  auto session = TransmitterSession::acquire(sessionFor(*device));
  ASSERT_EQ(session->waitLoggedIn(milliseconds(3000)), std::nullopt);
  auto status = session->status();
  EXPECT_EQ(status.cameraCount, 2);
  for (int i = 0; i < 50 && !session->status().hasControl; ++i)
    std::this_thread::sleep_for(milliseconds(10));
  EXPECT_TRUE(session->status().hasControl);
}

TEST(TransmitterSession, IsSharedByEveryUserOfTheSameDevice) {
  auto device = startDevice({.port = 0});
  auto a = TransmitterSession::acquire(sessionFor(*device));
  auto b = TransmitterSession::acquire(sessionFor(*device));
  EXPECT_EQ(a.get(), b.get());
  ASSERT_EQ(a->waitLoggedIn(milliseconds(3000)), std::nullopt);
  // The device publishes its counters just after it answers.
  for (int i = 0; i < 100 && device->stats().logins == 0; ++i)
    std::this_thread::sleep_for(milliseconds(5));
  EXPECT_EQ(device->stats().logins, 1u);
}

TEST(TransmitterSession, ReportsARefusedConnection) {
  auto device = startDevice({.port = 0});
  uint16_t port = device->port();
  device.reset();  // nothing listens there now
  auto session =
      TransmitterSession::acquire({.host = "127.0.0.1", .port = port, .reconnect = false});
  auto error = session->waitLoggedIn(milliseconds(3000));
  ASSERT_TRUE(error.has_value());
  EXPECT_NE(error->find("cannot connect"), std::string::npos) << *error;
}

TEST(TransmitterSession, KeepsPcdFlowingWhileNoCommandsCome) {
  auto device = startDevice({.port = 0});
  auto session = TransmitterSession::acquire(sessionFor(*device));
  ASSERT_EQ(session->waitLoggedIn(milliseconds(3000)), std::nullopt);
  ChannelValues drive = neutralChannels();
  drive[1] = 1700;
  session->setCommand(drive);
  std::this_thread::sleep_for(milliseconds(100));
  EXPECT_EQ(device->outputs().pulses[1], 1700);
  // The "pipeline" stalls: no command for 2 s. PCD must go on, now neutral.
  std::this_thread::sleep_for(milliseconds(2000));
  auto stats = device->stats();
  EXPECT_EQ(device->outputs().pulses[1], kPulseNeutral);
  EXPECT_FALSE(device->outputs().failsafe);
  EXPECT_GT(stats.pcdReceived, 90u);  // 50 Hz for 2.1 s
  EXPECT_LE(stats.maxPcdGap.count(), 60);
  EXPECT_EQ(stats.failsafeEntries, 0u);
}

TEST(TransmitterSession, ClampsCommandsIntoThePulseRange) {
  auto device = startDevice({.port = 0});
  auto session = TransmitterSession::acquire(sessionFor(*device));
  ASSERT_EQ(session->waitLoggedIn(milliseconds(3000)), std::nullopt);
  ChannelValues wild = neutralChannels();
  wild[0] = 5000;
  wild[1] = 10;
  session->setCommand(wild);
  std::this_thread::sleep_for(milliseconds(100));
  EXPECT_EQ(device->outputs().pulses[0], kPulseMax);
  EXPECT_EQ(device->outputs().pulses[1], kPulseMin);
  EXPECT_EQ(device->stats().pcdRejected, 0u);
}

TEST(TransmitterSession, ReconnectsAfterTheDeviceRestarts) {
  auto device = startDevice({.port = 0});
  uint16_t port = device->port();
  auto session = TransmitterSession::acquire(sessionFor(*device));
  ASSERT_EQ(session->waitLoggedIn(milliseconds(3000)), std::nullopt);
  device.reset();
  for (int i = 0; i < 100 && session->status().state == SessionState::LoggedIn; ++i)
    std::this_thread::sleep_for(milliseconds(10));
  EXPECT_NE(session->status().state, SessionState::LoggedIn);

  device = startDevice({.port = port});
  for (int i = 0; i < 600 && session->status().state != SessionState::LoggedIn; ++i)
    std::this_thread::sleep_for(milliseconds(10));
  EXPECT_EQ(session->status().state, SessionState::LoggedIn);
  EXPECT_EQ(session->status().logins, 2u);
}

TEST(TransmitterSession, ListsTheLoggedInTransmitters) {
  auto device = startDevice({.port = 0});
  auto session = TransmitterSession::acquire(sessionFor(*device, "lister"));
  ASSERT_EQ(session->waitLoggedIn(milliseconds(3000)), std::nullopt);
  auto list = session->listTransmitters(milliseconds(2000));
  ASSERT_TRUE(list.has_value());
  ASSERT_EQ(list->size(), 1u);
  EXPECT_EQ((*list)[0].name, "lister");
}

TEST(TransmitterSession, ConfigurationErrorsComeBackAsErr) {
  auto device = startDevice({.port = 0});
  auto first = TransmitterSession::acquire(sessionFor(*device));
  ASSERT_EQ(first->waitLoggedIn(milliseconds(3000)), std::nullopt);
  EXPECT_EQ(first->sendConfiguration(Dcfg{.name = "new-name"}, milliseconds(300)), std::nullopt);
  // Another name for the same device: a second session, a second transmitter.
  auto second = TransmitterSession::acquire(
      {.host = "localhost", .port = device->port(), .transmitterName = "second"});
  ASSERT_EQ(second->waitLoggedIn(milliseconds(3000)), std::nullopt);
  auto err = second->sendConfiguration(Dcfg{.name = "stolen"}, milliseconds(1000));
  ASSERT_TRUE(err.has_value());
  EXPECT_EQ(err->code, static_cast<uint16_t>(ErrorCode::Denied));
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
