#include "sim_options.h"

#include <cstdio>
#include <sstream>

#include "marvelmind/position_client.h"

namespace wircam::sim {

namespace {

using command_line::Apply;
using command_line::number;
using command_line::Problem;
using command_line::whole;

constexpr const char* kDevice = "Device";
constexpr const char* kScene = "Scene";
constexpr const char* kPositions = "Marvelmind indoor positions";
constexpr const char* kImpairments =
    "Impairments of the video stream (all seeded by --seed, repeatable)";

Apply version(wirc::Version& field) {
  return [&field](const char* value) -> Problem {
    unsigned major = 0, minor = 0;
    char end = 0;
    if (std::sscanf(value, "%u.%u%c", &major, &minor, &end) != 2 || major > 255 || minor > 255)
      return std::string("wants MAJOR.MINOR, not '") + value + "'";
    field = {static_cast<uint8_t>(major), static_cast<uint8_t>(minor)};
    return std::nullopt;
  };
}

Apply pictureSize(int& width, int& height) {
  return [&width, &height](const char* value) -> Problem {
    int w = 0, h = 0;
    char end = 0;
    if (std::sscanf(value, "%dx%d%c", &w, &h, &end) != 2 || w < 16 || h < 16 || w > 7680 ||
        h > 4320)
      return std::string("wants WIDTHxHEIGHT (16x16..7680x4320), not '") + value + "'";
    width = w, height = h;
    return std::nullopt;
  };
}

Apply tagIds(std::vector<int>& field) {
  return [&field](const char* value) -> Problem {
    std::vector<int> ids;
    std::stringstream list(value);
    for (std::string item; std::getline(list, item, ',');) {
      int id = 0;
      if (auto problem = whole(id, 0, 1e6)(item.c_str()))
        return "wants a list like 0,3,7: '" + item + "' " + *problem;
      ids.push_back(id);
    }
    if (ids.empty()) return "wants a list like 0,3,7";
    field = ids;
    return std::nullopt;
  };
}

std::vector<command_line::Section> sections(SimOptions& o) {
  auto& device = o.device;
  auto& scene = o.scene;
  auto& impairments = o.device.impairments;
  // A --marvelmind-* option makes the dashboard's settings; --marvelmind
  // runs it (checked after parsing).
  auto dashboard = [&o]() -> DashboardConfig& {
    if (!o.dashboard) o.dashboard.emplace();
    return *o.dashboard;
  };
  auto onDashboard = [dashboard](auto read) -> Apply {
    return [dashboard, read](const char* value) { return read(dashboard())(value); };
  };
  return {
      {kDevice,
       {
           {"port", "N", "1984",
            "TCP control and UDP discovery port (0 = pick a free one). The port is printed on "
            "stdout",
            whole(device.port, 0, 65535)},
           {"bind", "ADDR", "127.0.0.1", "address to listen on",
            command_line::text(device.bindAddress)},
           {"name", "NAME", "wirc-sim", "device name in BCSA, up to 64 characters",
            command_line::text(device.name)},
           {"serial", "SERIAL", "SIM0001", "serial number in BCSA, up to 7 characters",
            command_line::text(device.serial)},
           {"hw-version", "M.m", "1.0", "hardware version in BCSA", version(device.hardware)},
           {"sw-version", "M.m", "1.3", "software version in BCSA", version(device.software)},
           {"cameras", "N", "1", "number of cameras", whole(device.cameras, 1, 255)},
           {"fps", "F", "15", "frames per second per camera", number(device.fps, 0.1, 240)},
           {"size", "WxH", "352x288, CIF", "picture size", pictureSize(scene.width, scene.height)},
           {"quality", "Q", "85", "JPEG quality 1..100", whole(scene.jpegQuality, 1, 100)},
           {"fragment", "BYTES", "64512, the device's", "payload bytes per UDP packet",
            whole(device.fragmentSize, 1, 65491)},
           {"pcd-timeout", "MS", "800", "failsafe after this long without PCD",
            [&device](const char* value) -> Problem {
              int ms = 0;
              if (auto problem = whole(ms, 200, 2000)(value)) return problem;
              device.pcdTimeout = std::chrono::milliseconds(ms);
              return std::nullopt;
            }},
           {"duration", "S", nullptr, "stop after S seconds; without it, at SIGINT or SIGTERM",
            [&o](const char* value) -> Problem {
              double seconds = 0;
              if (auto problem = number(seconds, 0, 1e7)(value)) return problem;
              o.duration = seconds;
              return std::nullopt;
            }},
       }},
      {kScene,
       {
           {"scene", "follow|static", "follow",
            "follow: the car drives by PCD; static: the car stays put, the target still moves",
            command_line::choice<bool>(scene.carFixed, {{"follow", false}, {"static", true}})},
           {"clock-stamp", nullptr, nullptr,
            "draw the wall clock's milliseconds (mod 2^32) as 32 black/white blocks across the "
            "top of each frame, most significant first, for latency measurements",
            command_line::flag(scene.clockStamp)},
           {"frames", "DIR", nullptr,
            "stream the .jpg/.jpeg files of DIR in name order, byte for byte, looping (instead "
            "of a rendered scene)",
            command_line::optionalText(o.framesDir)},
           {"replay", "PATH", nullptr,
            "replay a recorded drive as the live camera: PATH is a wirc-recorder segment (.mkv "
            "of JPEG) or its folder (the segments in index order); each frame byte for byte at "
            "its recorded time, outages as outages (a pause over 10 s shortened to 10 s), the "
            "battery from the sidecars. Stops at the end with a summary",
            command_line::optionalText(o.replayPath)},
           {"camera", "NAME", nullptr, "the camera to replay from a folder holding several",
            command_line::text(o.replayCamera)},
           {"speed", "X", "1", "replay X times as fast", number(o.replay.speed, 0.01, 100)},
           {"loop", nullptr, nullptr, "replay again from the start at the end",
            command_line::flag(o.replay.loop)},
           {"commands-out", "FILE", nullptr,
            "write every PCD received with the frame on screen as it came: JSON lines "
            "{\"frame\", \"pts\", \"segment\", \"channels\", \"arrival_ms\"} (`wirc-cli "
            "compare-commands`)",
            command_line::text(o.replay.commandsOut)},
           {"family", "NAME", "tag36h11", "tag family", command_line::text(scene.family)},
           {"tags", "ID[,ID...]", "0", "tag ids; the first rides on the target",
            tagIds(scene.tagIds)},
           {"tag-size", "M", "0.16", "tag edge (black border) in metres",
            number(scene.tagSize, 0.01, 10)},
           {"path", "still|line|circle", "circle", "target path",
            [&scene](const char* value) -> Problem {
              auto path = parseTargetPath(value);
              if (!path) return path.error();
              scene.path = *path;
              return std::nullopt;
            }},
           {"target-speed", "M/S", "0.3", "target speed", number(scene.targetSpeed, 0, 10)},
           {"start-distance", "M", "1.2", "camera to target at the start",
            number(scene.startDistance, 0.2, 100)},
           {"follow-distance", "M", "1.0", "set point the summary measures against",
            number(scene.followDistance, 0.1, 100)},
           {"control", "wirc|rcoip|btemp", "wirc",
            "what steers the car: wirc, the PCD above; rcoip, an RCOIP receiver (replies at "
            "most once a second, to the sender only, fails safe after 2 s); btemp, a BTEMP "
            "robot (answers PING, RCTR and CTRL, sends PINS). The camera streams over WiRC "
            "MJPEG either way",
            command_line::oneOf(o.control, {"wirc", "rcoip", "btemp"})},
           {"control-port", "N", "9048 for rcoip, 16980 for btemp",
            "UDP port of that receiver or robot (0 = pick a free one, printed)",
            command_line::optionalWhole(o.controlPort, 0, 65535)},
           {"steering-channel", "N", "1", "PCD channel steering the car, 1..8 (2000 = left)",
            whole(scene.steeringChannel, 1, 8)},
           {"throttle-channel", "N", "2", "PCD channel driving the car, 1..8 (1500 = stop)",
            whole(scene.throttleChannel, 1, 8)},
           {"truth", "FILE", nullptr, "write the truth per frame as JSON lines",
            command_line::optionalText(o.truthPath)},
       }},
      {kPositions,
       {
           {"marvelmind", "PORT", nullptr,
            "run a Marvelmind dashboard on UDP PORT (0 = pick a free one, printed) reporting "
            "the scene's truth: the first beacon rides on the car, the second on the target, "
            "further ones stand still",
            [dashboard, &o](const char* value) {
              o.dashboardRuns = true;
              return whole(dashboard().port, 0, 65535)(value);
            }},
           {"marvelmind-beacons", "A[,B...]", "5", "beacon addresses, 1..254",
            onDashboard([](DashboardConfig& d) -> Apply {
              return [&d](const char* value) -> Problem {
                auto beacons = marvelmind::parseBeacons(value);
                if (!beacons) return beacons.error();
                d.beacons = *beacons;
                return std::nullopt;
              };
            })},
           {"marvelmind-rate", "HZ", "16", "measurements per second",
            onDashboard([](DashboardConfig& d) { return number(d.rate, 0.1, 100); })},
           {"marvelmind-noise", "M", "0.02 m", "standard deviation of each coordinate",
            onDashboard([](DashboardConfig& d) { return number(d.noise, 0, 10); })},
           {"marvelmind-dropout", "P", "0", "probability a measurement is missed",
            onDashboard([](DashboardConfig& d) { return number(d.dropout, 0, 1); })},
           {"marvelmind-push", "HOST:PORT", nullptr,
            "also push each measurement there (stream mode)",
            onDashboard([](DashboardConfig& d) -> Apply {
              return [&d](const char* value) -> Problem {
                std::string text = value;
                auto colon = text.rfind(':');
                uint16_t port = 0;
                if (colon == std::string::npos ||
                    whole(port, 1, 65535)(text.substr(colon + 1).c_str()))
                  return "wants HOST:PORT, not '" + text + "'";
                auto address = SocketAddress::resolve(text.substr(0, colon), port);
                if (!address) return address.error();
                d.pushTo = *address;
                return std::nullopt;
              };
            })},
           {"marvelmind-push-units", "cm|mm", "cm", "what the pushes carry",
            onDashboard([](DashboardConfig& d) {
              return command_line::choice<marvelmind::Resolution>(
                  d.pushResolution, {{"cm", marvelmind::Resolution::kCentimetres},
                                     {"mm", marvelmind::Resolution::kMillimetres}});
            })},
           {"marvelmind-timestamp", "64|ms", "64",
            "timestamp unit: 1/64 s as the protocol text says, or ms as newer dashboards",
            onDashboard([](DashboardConfig& d) {
              return command_line::choice<marvelmind::TimestampUnit>(
                  d.timestampUnit, {{"64", marvelmind::TimestampUnit::kSixtyFourths},
                                    {"ms", marvelmind::TimestampUnit::kMilliseconds}});
            })},
       }},
      {kImpairments,
       {
           {"loss", "P", "0", "probability a packet is lost", number(impairments.loss, 0, 1)},
           {"burst-loss", "P", "0", "probability a loss burst starts at a packet",
            number(impairments.burstLoss, 0, 1)},
           {"burst-length", "N", "5", "packets lost per burst",
            whole(impairments.burstLength, 1, 10000)},
           {"duplicate", "P", "0", "probability a packet is sent twice",
            number(impairments.duplication, 0, 1)},
           {"reorder", "N", "0", "hold N packets back and release them in random order",
            whole(impairments.reorderDepth, 0, 1000)},
           {"jitter", "BYTES", "0", "vary the fragment size by up to ±BYTES",
            whole(impairments.fragmentJitter, 0, 65000)},
           {"start-frame", "N", "0", "first frame number (e.g. 4294967290 to test wrap-around)",
            whole(impairments.startFrameNumber, 0, 4294967295.0)},
           {"reserved-bits", nullptr, nullptr, "set the version's reserved bits 31..17",
            command_line::flag(impairments.reservedBits)},
           {"stray", "P", "0", "per frame, probability of a forged packet from another port",
            number(impairments.strayRate, 0, 1)},
           {"misdirect", "PORT", nullptr,
            "stream to this port of the receiver instead of the one it asked for (a NAT or "
            "firewall that maps it wrong)",
            whole(impairments.misdirectPort, 1, 65535)},
           {"seed", "N", "1", "random seed", whole(impairments.seed, 0, 4294967295.0)},
       }},
  };
}

constexpr const char* kIntro = R"(Usage: wirc-sim [OPTIONS]

A WiRC device (protocol v1.3) on this machine: discovery on UDP, login and
control on TCP, PCD with failsafe, PSD, and MJPEG camera streams. The default
scene is a car whose camera follows an AprilTag target, driven by the PCD it
receives; --frames streams JPEG files instead.
)";

constexpr const char* kOutro = R"(
  -h, --help           show this text

On exit (SIGINT, SIGTERM or --duration) it prints a summary: frames sent, PCD
received, the longest PCD gap, failsafe entries, and how well the car followed.
)";

}  // namespace

command_line::CommandLine simCommandLine(SimOptions& options) {
  return command_line::CommandLine(sections(options));
}

std::string simUsage() {
  SimOptions unused;
  return kIntro + simCommandLine(unused).help() + kOutro;
}

Expected<std::optional<SimOptions>, std::string> parseSimOptions(int argc, char** argv) {
  SimOptions o;
  bool help = false;
  auto rest = simCommandLine(o).parse(argc, argv, &help);
  if (!rest) return unexpected(rest.error());
  if (help) return std::optional<SimOptions>();
  if (!rest->empty()) return unexpected("unexpected argument '" + rest->front() + "'");
  if (o.device.serial.size() > wirc::kSerialWidth)
    return unexpected("--serial is at most 7 characters");
  if (o.device.name.size() > wirc::kNameWidth) return unexpected("--name is at most 64 characters");
  if (o.dashboard && !o.dashboardRuns)
    return unexpected("the --marvelmind-* options need --marvelmind PORT");
  if (o.framesDir && o.replayPath) return unexpected("--frames and --replay: one scene at a time");
  if (!o.replayPath && (!o.replayCamera.empty() || o.replay.loop || o.replay.speed != 1 ||
                        !o.replay.commandsOut.empty()))
    return unexpected("--camera, --speed, --loop and --commands-out go with --replay");
  return std::optional<SimOptions>(std::move(o));
}

}  // namespace wircam::sim
