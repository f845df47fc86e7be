// wirc-sim's command line: every option declared once (common/
// command_line.h), from which it is parsed and --help and docs/tools.md's
// tables are made, and the checks of options that go together.
#pragma once

#include <optional>
#include <string>

#include "common/command_line.h"
#include "common/expected.h"
#include "devices/wirc/device.h"
#include "follow_scene.h"
#include "marvelmind_dashboard.h"
#include "replay/replay_scene.h"

namespace wircam::sim {

struct SimOptions {
  wirc::DeviceConfig device;
  FollowSceneConfig scene;
  std::optional<std::string> framesDir, truthPath, replayPath;
  std::string replayCamera;
  ReplayScene::Options replay;
  std::optional<double> duration;
  std::string control = "wirc";
  std::optional<uint16_t> controlPort;
  std::optional<DashboardConfig> dashboard;  // made by any --marvelmind* option
  bool dashboardRuns = false;                // --marvelmind PORT given
};

// The declaration, its values read into `options` (which must outlive it).
command_line::CommandLine simCommandLine(SimOptions& options);
// The whole of --help.
std::string simUsage();

// argv read and checked; nothing when --help was asked for, or why not.
Expected<std::optional<SimOptions>, std::string> parseSimOptions(int argc, char** argv);

}  // namespace wircam::sim
