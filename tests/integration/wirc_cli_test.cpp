// wirc-cli as a user runs it, against the simulated device.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <string>

#include "wait_for.h"
#include "wirc/device.h"
#include "wirc/transmitter_session.h"

namespace wircam::wirc {
namespace {

using std::chrono::milliseconds;

struct Run {
  int exitCode;
  std::string output;  // stdout and stderr
};

Run wircCli(const std::string& arguments) {
  std::string command = std::string(WIRCAM_BIN_DIR) + "/wirc-cli " + arguments + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  Run run{-1, ""};
  std::array<char, 256> chunk;
  while (size_t n = fread(chunk.data(), 1, chunk.size(), pipe)) run.output.append(chunk.data(), n);
  int status = pclose(pipe);
  run.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return run;
}

TEST(WircCli, RequestControlExitsOneWithTheReasonWhenTheDeviceDenies) {
  auto device = std::move(*Device::start({.port = 0}, nullptr));
  // A transmitter of higher priority holds the right.
  auto boss = TransmitterSession::acquire(
      {.host = "127.0.0.1", .port = device->port(), .transmitterName = "boss", .priority = 9});
  ASSERT_TRUE(boss.has_value());
  ASSERT_EQ((*boss)->waitLoggedIn(milliseconds(3000)), std::nullopt);
  auto run = wircCli("request-control 2 --host 127.0.0.1 --port " + std::to_string(device->port()));
  EXPECT_EQ(run.exitCode, 1) << run.output;
  EXPECT_NE(run.output.find("denied"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("boss"), std::string::npos) << run.output;
}

TEST(WircCli, RequestControlExitsZeroWhenGranted) {
  auto device = std::move(*Device::start({.port = 0}, nullptr));
  auto run = wircCli("request-control 1 --host 127.0.0.1 --port " + std::to_string(device->port()) +
                     " --priority 5");
  EXPECT_EQ(run.exitCode, 0) << run.output;
}

TEST(WircCli, WifiNeedsACountryCode) {
  auto run = wircCli("wifi --ssid lab --host 127.0.0.1");
  EXPECT_EQ(run.exitCode, 2) << run.output;
  EXPECT_NE(run.output.find("--country"), std::string::npos) << run.output;
}

TEST(WircCli, ExtoutSendsBytesToANamedDestination) {
  auto device = std::move(*Device::start({.port = 0}, nullptr));
  auto run = wircCli("extout --destination uart --data 'de ad be ef' --host 127.0.0.1 --port " +
                     std::to_string(device->port()));
  EXPECT_EQ(run.exitCode, 0) << run.output;
  EXPECT_NE(run.output.find("4 bytes sent to port 0x01"), std::string::npos) << run.output;
}

TEST(WircCli, ExtoutRefusesMoreBytesThanTheMessageCarries) {
  auto run = wircCli("extout --destination spi-data --data " + std::string(2 * 255, 'a') +
                     " --host 127.0.0.1");
  EXPECT_EQ(run.exitCode, 2) << run.output;
}

TEST(WircCli, FirmwareUpdateRestartsTheDevice) {
  auto device = std::move(*Device::start({.port = 0, .restartTime = milliseconds(100)}, nullptr));
  auto run = wircCli(
      "firmware-update --md5 00112233445566778899aabbccddeeff --host 127.0.0.1 "
      "--port " +
      std::to_string(device->port()));
  EXPECT_EQ(run.exitCode, 0) << run.output;
  EXPECT_TRUE(testing::waitFor([&] { return device->stats().restarts == 1; }));
  auto bad = wircCli("firmware-update --md5 0011 --host 127.0.0.1");
  EXPECT_EQ(bad.exitCode, 2) << bad.output;
}

}  // namespace
}  // namespace wircam::wirc
