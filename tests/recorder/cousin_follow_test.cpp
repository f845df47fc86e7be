// wirc-recorder --follow with control=rcoip://… or btemp://…: the WiRC
// camera is recorded while the tags steer an RCOIP receiver or a BTEMP
// robot, and that vehicle's link and status join the telemetry.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "devices/wirc/device.h"
#include "follow_scene.h"
#include "recorder_process.h"
#include "vehicle_control.h"

namespace {

namespace fs = std::filesystem;
using namespace wircam;
using namespace wircam::testing;

class RecorderCousinFollow : public ::testing::TestWithParam<const char*> {};

TEST_P(RecorderCousinFollow, SteersTheVehicleOfControlAndRecordsItsStatus) {
  std::string protocol = GetParam();
  auto control = sim::startVehicleControl(protocol, "127.0.0.1", 0, {});
  ASSERT_TRUE(control);
  auto* car = control->get();
  auto scene = sim::FollowScene::create({});
  ASSERT_TRUE(scene);
  auto device = wirc::Device::start(
      {.port = 0,
       .fragmentSize = 8000,
       .carControl = [car](wirc::DeviceClock::time_point now) { return car->outputs(now); }},
      std::shared_ptr<sim::FollowScene>(std::move(*scene)));
  ASSERT_TRUE(device);
  std::string uri = protocol + "://127.0.0.1:" + std::to_string(car->port());
  auto folder =
      fs::temp_directory_path() / ("wirc-recorder-" + protocol + "-" + std::to_string(getpid()));
  fs::remove_all(folder);
  fs::create_directories(folder);
  std::vector<std::string> args = {"--detect", "tag36h11", "--follow", "--duration", "4"};
  // One protocol from the command line, the other from a config file.
  if (protocol == "rcoip") {
    args.insert(args.end(), {"--out", (folder / "out").string(), "--device",
                             "127.0.0.1:" + std::to_string((*device)->port()) + ",control=" + uri});
  } else {
    auto config = folder / "recorder.ini";
    std::ofstream(config) << "[recorder]\nout=" << (folder / "out").string()
                          << "\n[device robot]\nhost=127.0.0.1\nport=" << (*device)->port()
                          << "\ncontrol=" << uri << "\n";
    args.insert(args.end(), {"--config", config.string()});
  }
  RecorderProcess recorder(0, args);
  ASSERT_EQ(recorder.wait(), 0) << recorder.log();
  // A command per change at least, over the seconds of following.
  EXPECT_GT(car->commandsReceived(), 10u) << car->summary();
  bool live = false, status = false;
  for (const auto& entry : fs::directory_iterator(folder / "out")) {
    if (entry.path().extension() != ".jsonl") continue;
    std::ifstream in(entry.path());
    for (std::string text; std::getline(in, text);) {
      auto line = nlohmann::json::parse(text);
      if (line["type"] != "vehicle") continue;
      live = live || line.value("state", "") == "live";
      if (protocol == "rcoip") status = status || line.contains("battery-v");
      if (protocol == "btemp") status = status || line.contains("pdm-duty");
    }
  }
  EXPECT_TRUE(live) << recorder.log();
  EXPECT_TRUE(status) << "no status report of the " << protocol << " vehicle in the telemetry";
  fs::remove_all(folder);
}

INSTANTIATE_TEST_SUITE_P(Protocols, RecorderCousinFollow, ::testing::Values("rcoip", "btemp"));

TEST(RecorderCousinFollow, RefusesAControlUriItCannotUse) {
  for (const char* bad : {"127.0.0.1:1984,control=http://x", "127.0.0.1:1984,control=rcoip://",
                          "127.0.0.1:1984,steer=rcoip://x"}) {
    RecorderProcess recorder(
        0, std::vector<std::string>{"--device", bad, "--detect", "tag36h11", "--follow"});
    EXPECT_EQ(recorder.wait(), 2) << bad << "\n" << recorder.log();
  }
}

}  // namespace
