// wirc-cli: talk to a WiRC device (or wirc-sim) from a shell. See --help.
// The commands are a table; the RCOIP and BTEMP vehicles and the Marvelmind
// positions have their own (cousin_commands, positions_command).
#include <algorithm>
#include <cstdio>
#include <fstream>
#include <string>

#include "cli_options.h"
#include "command_comparison.h"
#include "cousin_commands.h"
#include "positions_command.h"
#include "wirc_commands.h"

using namespace wircam::cli;

namespace {

struct Command {
  const char* name;
  int (*run)(const Options&);
  int arguments = 0;  // positional arguments it takes; -1: checked by the command
};

// compare-commands RECORDED... REPLAYED: exit 1 when a file cannot be read.
int compareCommandFiles(const Options& o) {
  if (o.positional.size() < 2)
    usageError("compare-commands takes RECORDED (sidecars or a recordings folder) and REPLAYED");
  std::vector<std::string> recordedPaths(o.positional.begin(), o.positional.end() - 1);
  const std::string& replayedPath = o.positional.back();
  std::ifstream replayedFile(replayedPath);
  if (!replayedFile) {
    std::fprintf(stderr, "wirc-cli: cannot read %s\n", replayedPath.c_str());
    return 1;
  }
  auto recorded = recordedCommandsIn(recordedPaths);
  if (!recorded) {
    std::fprintf(stderr, "wirc-cli: %s\n", recorded.error().c_str());
    return 1;
  }
  auto replayed = replayedCommands(replayedFile);
  if (!replayed) {
    std::fprintf(stderr, "wirc-cli: %s: %s\n", replayedPath.c_str(), replayed.error().c_str());
    return 1;
  }
  auto comparison = compareCommands(*recorded, *replayed);
  if (comparison.frames == 0) {
    // Nothing to compare is no agreement: most likely the replay of another drive.
    std::fprintf(stderr,
                 "wirc-cli: no frame of %s is in the recording (the same segment and time): is "
                 "it the replay of this drive?\n",
                 replayedPath.c_str());
    return 1;
  }
  std::fputs(o.json ? (comparisonJson(comparison).dump() + "\n").c_str()
                    : comparisonText(comparison).c_str(),
             stdout);
  return 0;
}

// A WiRC device's commands.
constexpr Command kWircCommands[] = {
    {"discover", discover},
    {"info", info},
    {"transmitters", transmitters},
    {"request-control", requestControl, 1},
    {"configure", configure},
    {"set-name", setName, 1},
    {"extout", extout},
    {"firmware-update", firmwareUpdate},
    {"wifi", wifi},
    {"stream", stream},
    {"drive", drive},
    {"decode", decode},
    {"encode", encode},
    {"compare-commands", compareCommandFiles, -1},
};

int positions(Options& o) {
  if (o.positions.dashboard.empty() || o.positions.beacons.empty())
    usageError("positions needs --marvelmind HOST:PORT and --beacon ADDR");
  o.positions.timeout = o.timeout;
  return printPositions(o.positions);
}

// --protocol rcoip|btemp: drive, info and (BTEMP) discover.
int cousin(const std::string& command, const Options& o) {
  CousinOptions cousin{.protocol = o.protocol,
                       .host = o.host,
                       .port = static_cast<uint16_t>(o.portGiven ? o.port : 0),
                       .broadcastAddress = o.discoveryAddress,
                       .timeout = o.timeout,
                       .steering = o.steering.value_or(1500),
                       .throttle = o.throttle.value_or(1500),
                       .seconds = std::min(o.duration > 0 ? o.duration : 1.0, 10.0)};
  if (command == "drive") {
    if (!o.steering || !o.throttle)
      usageError("drive needs --steering US and --throttle US (800..2200)");
    return driveCousin(cousin);
  }
  if (command == "info") return infoCousin(cousin);
  if (command == "discover" && o.protocol == "btemp") return discoverBtemp(cousin);
  usageError(command + " is for WiRC devices only (--protocol " + o.protocol + " has drive, info" +
             (o.protocol == "btemp" ? ", discover)" : ")"));
}

}  // namespace

int main(int argc, char** argv) {
  std::string command = argc > 1 ? argv[1] : "help";
  if (command == "help" || command == "--help" || command == "-h") {
    std::fputs(cliUsage().c_str(), stdout);
    return 0;
  }
  Options o = parse(argc, argv);
  // An argument a command does not take is a mistake, not to be ignored.
  auto takes = [&](size_t arguments) {
    if (o.positional.size() == arguments) return;
    if (arguments == 0) usageError(command + " takes no argument, not '" + o.positional[0] + "'");
    usageError(command + " takes " + std::to_string(arguments) + " argument" +
               (arguments == 1 ? "" : "s"));
  };
  if (command == "positions") {
    takes(0);
    return positions(o);
  }
  if (o.protocol != "wirc") {
    takes(0);
    return cousin(command, o);
  }
  for (const Command& c : kWircCommands) {
    if (command != c.name) continue;
    if (c.arguments >= 0) takes(static_cast<size_t>(c.arguments));
    return c.run(o);
  }
  usageError("unknown command '" + command + "'");
}
