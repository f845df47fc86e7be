// wirc-cli as a user runs it, against the simulated device.
#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <regex>
#include <sstream>
#include <string>

#include "devices/btemp/btemp_robot.h"
#include "devices/rcoip/rcoip_receiver.h"
#include "devices/wirc/device.h"
#include "marvelmind_dashboard.h"
#include "misbehaving_peers.h"
#include "shell_command.h"
#include "wait_for.h"
#include "wirc/transmitter_session.h"

namespace wircam::wirc {
namespace {

using std::chrono::milliseconds;
using testing::CommandRun;
using testing::runCommand;

CommandRun wircCli(const std::string& arguments) {
  return runCommand(std::string(WIRCAM_BIN_DIR) + "/wirc-cli " + arguments);
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

TEST(WircCli, RequestControlForAConnectionNobodyHoldsSaysSo) {
  auto device = std::move(*Device::start({.port = 0}, nullptr));
  auto run = wircCli("request-control 9 --host 127.0.0.1 --port " + std::to_string(device->port()));
  EXPECT_EQ(run.exitCode, 1) << run.output;
  EXPECT_NE(run.output.find("no transmitter is logged in as connection 9"), std::string::npos)
      << run.output;
}

TEST(WircCli, RequestControlExitsZeroWhenGranted) {
  auto device = std::move(*Device::start({.port = 0}, nullptr));
  auto run = wircCli("request-control 1 --host 127.0.0.1 --port " + std::to_string(device->port()) +
                     " --priority 5");
  EXPECT_EQ(run.exitCode, 0) << run.output;
}

TEST(WircCli, TransmitterNamesWithC1ControlsAreEscaped) {
  // A device lists a transmitter named with CSI (0x9B, which a terminal
  // obeys as ESC [) and 0x92: Latin-1 C1 controls, not text.
  std::vector<uint8_t> tlst = {2, 5};
  std::string name =
      "evil\x9B"
      "2J\x92x";
  tlst.insert(tlst.end(), name.begin(), name.end());
  tlst.resize(2 + 64, 0);
  testing::ScriptedPeer peer;
  auto list = testing::framed(static_cast<uint8_t>(Command::Tlst), tlst);
  auto end = testing::bytesOf(Tlend{});
  list.insert(list.end(), end.begin(), end.end());
  // Over and over, so the list also answers the TLR sent after the login.
  peer.play({.chunks = {peer.wst()}, .flood = list});
  auto run = wircCli("transmitters --host 127.0.0.1 --port " + std::to_string(peer.port()));
  EXPECT_EQ(run.exitCode, 0) << run.output;
  EXPECT_NE(run.output.find("evil\\x9B2J\\x92x"), std::string::npos) << run.output;
  for (unsigned char c : run.output) EXPECT_NE(c, 0x9B) << run.output;
  EXPECT_EQ(run.output.find("\xC2\x9B"), std::string::npos);
}

TEST(WircCli, WifiNeedsACountryCode) {
  auto run = wircCli("wifi --ssid lab --host 127.0.0.1");
  EXPECT_EQ(run.exitCode, 2) << run.output;
  EXPECT_NE(run.output.find("--country"), std::string::npos) << run.output;
}

// Found by a stranger's trial: `decode extra` and `info … extra` went on
// as if nothing were there.
TEST(WircCli, RefusesAnArgumentACommandDoesNotTake) {
  for (const char* line : {"decode extra", "info --host 127.0.0.1 --port 9 extra",
                           "drive --protocol rcoip --host 127.0.0.1 extra"}) {
    auto run = wircCli(line);
    EXPECT_EQ(run.exitCode, 2) << line << "\n" << run.output;
    EXPECT_NE(run.output.find("takes no argument, not 'extra'"), std::string::npos) << run.output;
  }
  auto run = wircCli("request-control --host 127.0.0.1 --port 9");
  EXPECT_EQ(run.exitCode, 2) << run.output;
  EXPECT_NE(run.output.find("request-control takes 1 argument"), std::string::npos) << run.output;
}

// Found by a stranger's trial: an option of another command (an --ssid
// given to info, --json to decode, --host to positions) was ignored; and
// what the device would refuse was refused only after logging in. Port 9
// (discard): nothing listens, so a refusal must come before any login.
TEST(WircCli, RefusesAnotherCommandsOptionAndWhatTheDeviceWouldRefuseBeforeLoggingIn) {
  const std::pair<const char*, const char*> cases[] = {
      {"info --host 127.0.0.1 --port 9 --ssid lab", "info does not take --ssid"},
      {"decode --json", "decode does not take --json"},
      {"positions --host 127.0.0.1 --marvelmind 127.0.0.1:9 --beacon 5",
       "positions does not take --host"},
      {"drive --protocol rcoip --host 127.0.0.1 --steering 1500 --throttle 1500 --md5 00",
       "drive does not take --md5"},
      {"set-name --host 127.0.0.1 --port 9 "
       "aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaa",
       "at most 64"},
      {"wifi --ssid lab --country USA --host 127.0.0.1 --port 9", "not 'USA'"},
      {"wifi --ssid lab --country 12 --host 127.0.0.1 --port 9", "not '12'"},
  };
  for (const auto& [line, said] : cases) {
    auto run = wircCli(line);
    EXPECT_EQ(run.exitCode, 2) << line << "\n" << run.output;
    EXPECT_NE(run.output.find(said), std::string::npos) << line << "\n" << run.output;
  }
}

// Found by a stranger's trial: decode printed nothing and exited 0 for
// input that held no message, and encode filled a misspelt field with 0.
TEST(WircCli, DecodeSaysWhatIsNoMessageAndEncodeWantsEveryField) {
  auto junk = runCommand("printf 'hello world' | " + std::string(WIRCAM_BIN_DIR) +
                         "/wirc-cli decode --raw");
  EXPECT_EQ(junk.exitCode, 1) << junk.output;
  EXPECT_NE(junk.output.find(R"("error":"garbage")"), std::string::npos) << junk.output;
  auto cut = runCommand("echo 'AA BB 01' | " + std::string(WIRCAM_BIN_DIR) + "/wirc-cli decode");
  EXPECT_EQ(cut.exitCode, 1) << cut.output;
  EXPECT_NE(cut.output.find(R"("error":"truncated")"), std::string::npos) << cut.output;
  auto misspelt = runCommand(R"(echo '{"type":"STST","camra":1,"port":5000}' | )" +
                             std::string(WIRCAM_BIN_DIR) + "/wirc-cli encode");
  EXPECT_EQ(misspelt.exitCode, 1) << misspelt.output;
  EXPECT_NE(misspelt.output.find(R"("camra" is no field of STST)"), std::string::npos)
      << misspelt.output;
}

TEST(WircCli, HelpFitsAnEightyColumnTerminal) {
  auto help = wircCli("--help");
  EXPECT_EQ(help.exitCode, 0);
  std::istringstream lines(help.output);
  std::string line;
  while (std::getline(lines, line)) {
    // Characters, not bytes (µ, Δ, ±).
    size_t width = 0;
    for (unsigned char c : line) width += (c & 0xC0) != 0x80;
    EXPECT_LE(width, 79u) << line;
  }
}

// A stream of a camera the device lacks is refused before the file is
// made (a stranger found an empty one left behind).
TEST(WircCli, AStreamOfACameraTheDeviceLacksLeavesNoFile) {
  auto device = std::move(*Device::start({.port = 0}, nullptr));
  auto out = std::filesystem::temp_directory_path() /
             ("wirc-cli-no-camera-" + std::to_string(getpid()) + ".mjpeg");
  auto run = wircCli("stream --camera 1 --frames 3 --host 127.0.0.1 --port " +
                     std::to_string(device->port()) + " --out " + out.string());
  EXPECT_EQ(run.exitCode, 1) << run.output;
  EXPECT_NE(run.output.find("the device has 1 camera: --camera 0"), std::string::npos)
      << run.output;
  EXPECT_FALSE(std::filesystem::exists(out));
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

// Throttle (channel 2) at neutral, give or take the codec's rounding.
template <typename Vehicle>
bool atNeutral(Vehicle& vehicle) {
  return std::abs(vehicle.outputs(std::chrono::steady_clock::now()).pulses[1] - 1500) <= 6;
}

// The cousin vehicles' command lines, word for word as the README gives them.
TEST(WircCli, DrivesAnRcoipReceiverThenNeutralAndShowsItsBattery) {
  auto receiver = rcoip::Receiver::start({.port = 0});
  ASSERT_TRUE(receiver);
  auto run = wircCli("drive --protocol rcoip --host 127.0.0.1 --port " +
                     std::to_string((*receiver)->port()) +
                     " --steering 1800 --throttle 1600 --duration 2");
  EXPECT_EQ(run.exitCode, 0) << run.output;
  EXPECT_NE(run.output.find("battery 11.12 V"), std::string::npos) << run.output;
  EXPECT_GT((*receiver)->stats().commands, 1u);
  // The last datagram may still wait for the receiver's thread when the
  // command line has exited.
  EXPECT_TRUE(testing::waitFor([&] { return atNeutral(**receiver); }))
      << "the last command was not neutral";
}

TEST(WircCli, DrivesABtempRobotAndShowsItsPins) {
  auto robot = btemp::Robot::start({.port = 0});
  ASSERT_TRUE(robot);
  std::string where = " --host 127.0.0.1 --port " + std::to_string((*robot)->port());
  auto drive =
      wircCli("drive --protocol btemp" + where + " --steering 1800 --throttle 1600 --duration 2");
  EXPECT_EQ(drive.exitCode, 0) << drive.output;
  EXPECT_NE(drive.output.find("PDM duty"), std::string::npos) << drive.output;
  EXPECT_GT((*robot)->stats().ctrl, 5u);
  EXPECT_TRUE(testing::waitFor([&] { return atNeutral(**robot); }));
  auto info = wircCli("info --protocol btemp" + where);
  EXPECT_EQ(info.exitCode, 0) << info.output;
  EXPECT_NE(info.output.find("(robot)"), std::string::npos) << info.output;
  auto found = wircCli("discover --protocol btemp" + where + " --timeout 500");
  EXPECT_EQ(found.exitCode, 0) << found.output;
  EXPECT_NE(found.output.find("robot"), std::string::npos) << found.output;
}

TEST(WircCli, SaysWhenNoRcoipReceiverAnswers) {
  auto run = wircCli("info --protocol rcoip --host 127.0.0.1 --port 9 --timeout 1200");
  EXPECT_EQ(run.exitCode, 1) << run.output;
  EXPECT_NE(run.output.find("no status report"), std::string::npos) << run.output;
  EXPECT_EQ(wircCli("transmitters --protocol rcoip --host 127.0.0.1").exitCode, 2);
}

TEST(WircCli, PrintsMarvelmindPositionsOnePerLineInTheExactForm) {
  auto dashboard = sim::MarvelmindDashboard::start(
      {.beacons = {5, 6}, .rate = 20, .noise = 0}, [](size_t index) {
        return std::array<double, 3>{1.25, -0.5 - static_cast<double>(index), 0.3};
      });
  ASSERT_TRUE(dashboard) << dashboard.error();
  auto address = "--marvelmind 127.0.0.1:" + std::to_string((*dashboard)->port());
  auto run = wircCli("positions " + address + " --beacon 6 --count 4");
  ASSERT_EQ(run.exitCode, 0) << run.output;
  // Scripts rely on this exact form: beacon, x, y, z (metres), timestamp (s).
  std::regex line(
      R"(\{"beacon":6,"x":1\.250,"y":-1\.500,"z":0\.300,"timestamp":[0-9]+\.[0-9]{3}\})");
  std::istringstream lines(run.output);
  std::string text;
  int count = 0;
  double previous = -1;
  while (std::getline(lines, text)) {
    EXPECT_TRUE(std::regex_match(text, line)) << text;
    double timestamp = std::stod(text.substr(text.rfind(':') + 1));
    EXPECT_GT(timestamp, previous);  // each a new measurement
    previous = timestamp;
    ++count;
  }
  EXPECT_EQ(count, 4);
}

TEST(WircCli, PositionsExitOneWhenTheDashboardIsSilent) {
  auto run = wircCli("positions --marvelmind 127.0.0.1:9 --beacon 5 --count 1 --timeout 300");
  EXPECT_EQ(run.exitCode, 1) << run.output;
  EXPECT_NE(run.output.find("no reply from the dashboard at 127.0.0.1:9"), std::string::npos)
      << run.output;
  EXPECT_EQ(wircCli("positions --marvelmind 127.0.0.1 --beacon 5 --count 1").exitCode, 2);
  EXPECT_EQ(wircCli("positions --marvelmind 127.0.0.1:9 --beacon 300 --count 1").exitCode, 2);
}

}  // namespace
}  // namespace wircam::wirc
