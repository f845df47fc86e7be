// wirc-sim: a complete WiRC device on this machine, for tests, demos and
// benchmarks. See --help.
#include <getopt.h>
#include <gst/gst.h>
#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <optional>
#include <sstream>
#include <string>

#include "devices/wirc/device.h"
#include "follow_scene.h"
#include "jpeg_sequence_scene.h"
#include "marvelmind/position_client.h"
#include "marvelmind_dashboard.h"
#include "replay/replay_scene.h"
#include "sim_usage.h"
#include "vehicle_control.h"

using namespace wircam;

namespace {

enum Option {
  kPort = 1000,
  kBind,
  kName,
  kSerial,
  kHwVersion,
  kSwVersion,
  kCameras,
  kFps,
  kSize,
  kQuality,
  kFragment,
  kPcdTimeout,
  kDuration,
  kScene,
  kClockStamp,
  kFrames,
  kReplay,
  kCamera,
  kSpeed,
  kLoop,
  kCommandsOut,
  kFamily,
  kTags,
  kTagSize,
  kPath,
  kTargetSpeed,
  kStartDistance,
  kFollowDistance,
  kSteeringChannel,
  kThrottleChannel,
  kTruth,
  kControl,
  kControlPort,
  kLoss,
  kBurstLoss,
  kBurstLength,
  kDuplicate,
  kReorder,
  kJitter,
  kStartFrame,
  kReservedBits,
  kStray,
  kMisdirect,
  kSeed,
  kMarvelmind,
  kMarvelmindBeacons,
  kMarvelmindRate,
  kMarvelmindNoise,
  kMarvelmindDropout,
  kMarvelmindPush,
  kMarvelmindPushUnits,
  kMarvelmindTimestamp,
};

const option kOptions[] = {
    {"port", required_argument, nullptr, kPort},
    {"bind", required_argument, nullptr, kBind},
    {"name", required_argument, nullptr, kName},
    {"serial", required_argument, nullptr, kSerial},
    {"hw-version", required_argument, nullptr, kHwVersion},
    {"sw-version", required_argument, nullptr, kSwVersion},
    {"cameras", required_argument, nullptr, kCameras},
    {"fps", required_argument, nullptr, kFps},
    {"size", required_argument, nullptr, kSize},
    {"quality", required_argument, nullptr, kQuality},
    {"fragment", required_argument, nullptr, kFragment},
    {"pcd-timeout", required_argument, nullptr, kPcdTimeout},
    {"duration", required_argument, nullptr, kDuration},
    {"scene", required_argument, nullptr, kScene},
    {"clock-stamp", no_argument, nullptr, kClockStamp},
    {"frames", required_argument, nullptr, kFrames},
    {"replay", required_argument, nullptr, kReplay},
    {"camera", required_argument, nullptr, kCamera},
    {"speed", required_argument, nullptr, kSpeed},
    {"loop", no_argument, nullptr, kLoop},
    {"commands-out", required_argument, nullptr, kCommandsOut},
    {"family", required_argument, nullptr, kFamily},
    {"tags", required_argument, nullptr, kTags},
    {"tag-size", required_argument, nullptr, kTagSize},
    {"path", required_argument, nullptr, kPath},
    {"target-speed", required_argument, nullptr, kTargetSpeed},
    {"start-distance", required_argument, nullptr, kStartDistance},
    {"follow-distance", required_argument, nullptr, kFollowDistance},
    {"steering-channel", required_argument, nullptr, kSteeringChannel},
    {"throttle-channel", required_argument, nullptr, kThrottleChannel},
    {"truth", required_argument, nullptr, kTruth},
    {"control", required_argument, nullptr, kControl},
    {"control-port", required_argument, nullptr, kControlPort},
    {"loss", required_argument, nullptr, kLoss},
    {"burst-loss", required_argument, nullptr, kBurstLoss},
    {"burst-length", required_argument, nullptr, kBurstLength},
    {"duplicate", required_argument, nullptr, kDuplicate},
    {"reorder", required_argument, nullptr, kReorder},
    {"jitter", required_argument, nullptr, kJitter},
    {"start-frame", required_argument, nullptr, kStartFrame},
    {"reserved-bits", no_argument, nullptr, kReservedBits},
    {"stray", required_argument, nullptr, kStray},
    {"misdirect", required_argument, nullptr, kMisdirect},
    {"seed", required_argument, nullptr, kSeed},
    {"marvelmind", required_argument, nullptr, kMarvelmind},
    {"marvelmind-beacons", required_argument, nullptr, kMarvelmindBeacons},
    {"marvelmind-rate", required_argument, nullptr, kMarvelmindRate},
    {"marvelmind-noise", required_argument, nullptr, kMarvelmindNoise},
    {"marvelmind-dropout", required_argument, nullptr, kMarvelmindDropout},
    {"marvelmind-push", required_argument, nullptr, kMarvelmindPush},
    {"marvelmind-push-units", required_argument, nullptr, kMarvelmindPushUnits},
    {"marvelmind-timestamp", required_argument, nullptr, kMarvelmindTimestamp},
    {"help", no_argument, nullptr, 'h'},
    {nullptr, 0, nullptr, 0},
};

[[noreturn]] void usageError(const std::string& message) {
  std::fprintf(stderr, "wirc-sim: %s (see wirc-sim --help)\n", message.c_str());
  std::exit(2);
}

double number(const char* text, const char* option, double min, double max) {
  char* end = nullptr;
  double value = std::strtod(text, &end);
  if (end == text || *end != '\0' || !std::isfinite(value) || value < min || value > max) {
    std::ostringstream message;
    message << "--" << option << " wants a number in " << min << ".." << max << ", not '" << text
            << "'";
    usageError(message.str());
  }
  return value;
}

wirc::Version version(const char* text, const char* option) {
  unsigned major = 0, minor = 0;
  if (std::sscanf(text, "%u.%u", &major, &minor) != 2 || major > 255 || minor > 255)
    usageError(std::string("--") + option + " wants MAJOR.MINOR, not '" + text + "'");
  return {static_cast<uint8_t>(major), static_cast<uint8_t>(minor)};
}

std::vector<int> idList(const char* text) {
  std::vector<int> ids;
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, ','))
    ids.push_back(static_cast<int>(number(item.c_str(), "tags", 0, 1e6)));
  if (ids.empty()) usageError("--tags wants a list like 0,3,7");
  return ids;
}

// Where the dashboard's beacons truly are: on the car and on the target, at
// the camera's height, then posts standing along the y = -3 m line. Without
// a rendered world (--frames) every beacon stands at the origin.
sim::MarvelmindDashboard::TruthSource beaconTruth(const sim::FollowScene* scene) {
  double height = scene ? scene->config().cameraHeight : 0;
  return [scene, height](size_t index) -> std::array<double, 3> {
    if (!scene) return {0, 0, 0};
    auto truth = scene->truthNow();
    if (index == 0) return {truth.car.x, truth.car.y, height};
    if (index == 1) return {truth.target.x, truth.target.y, height};
    return {2.0 * static_cast<double>(index - 1), -3, 1};
  };
}

std::string timestamp() {
  using namespace std::chrono;
  auto now = system_clock::now();
  auto seconds = system_clock::to_time_t(now);
  auto ms = duration_cast<milliseconds>(now.time_since_epoch()).count() % 1000;
  char text[32];
  std::strftime(text, sizeof text, "%H:%M:%S", std::localtime(&seconds));
  return std::string(text) + "." + std::to_string(1000 + ms).substr(1);
}

// The signal that ends the run (SIGINT, SIGTERM, SIGUSR1), or 0 at the end
// of `duration`. A stop and continue (Ctrl-Z, then fg) interrupts the wait
// (EINTR) without ending it: it ended the run once.
int waitForStop(const sigset_t& signals, std::optional<double> duration) {
  using Clock = std::chrono::steady_clock;
  auto end = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                std::chrono::duration<double>(duration.value_or(0)));
  while (true) {
    int caught;
    if (duration) {
      auto left = std::chrono::duration_cast<std::chrono::nanoseconds>(end - Clock::now());
      if (left.count() <= 0) return 0;
      timespec wait{static_cast<time_t>(left.count() / 1000000000),
                    static_cast<long>(left.count() % 1000000000)};
      caught = sigtimedwait(&signals, nullptr, &wait);
      if (caught < 0 && errno == EAGAIN) return 0;
    } else {
      caught = sigwaitinfo(&signals, nullptr);
    }
    if (caught > 0) return caught;
    if (errno != EINTR) return 0;
  }
}

}  // namespace

int main(int argc, char** argv) {
  wirc::DeviceConfig device;
  sim::FollowSceneConfig scene;
  std::optional<std::string> framesDir, truthPath, replayPath;
  struct {
    std::string camera;
    sim::ReplayScene::Options options;
  } replay;
  std::optional<double> duration;
  std::string control = "wirc";
  std::optional<uint16_t> controlPort;
  std::optional<sim::DashboardConfig> dashboard;
  auto dashboardConfig = [&]() -> sim::DashboardConfig& {
    if (!dashboard) dashboard.emplace();
    return *dashboard;
  };
  bool dashboardPort = false;

  int opt;
  while ((opt = getopt_long(argc, argv, "h", kOptions, nullptr)) != -1) {
    switch (opt) {
      case 'h':
        std::fputs(sim::kUsage, stdout);
        return 0;
      case kPort:
        device.port = static_cast<uint16_t>(number(optarg, "port", 0, 65535));
        break;
      case kBind:
        device.bindAddress = optarg;
        break;
      case kName:
        device.name = optarg;
        break;
      case kSerial:
        device.serial = optarg;
        break;
      case kHwVersion:
        device.hardware = version(optarg, "hw-version");
        break;
      case kSwVersion:
        device.software = version(optarg, "sw-version");
        break;
      case kCameras:
        device.cameras = static_cast<int>(number(optarg, "cameras", 1, 255));
        break;
      case kFps:
        device.fps = number(optarg, "fps", 0.1, 240);
        break;
      case kSize:
        if (std::sscanf(optarg, "%dx%d", &scene.width, &scene.height) != 2)
          usageError(std::string("--size wants WIDTHxHEIGHT, not '") + optarg + "'");
        break;
      case kQuality:
        scene.jpegQuality = static_cast<int>(number(optarg, "quality", 1, 100));
        break;
      case kFragment:
        device.fragmentSize = static_cast<size_t>(number(optarg, "fragment", 1, 65491));
        break;
      case kPcdTimeout:
        device.pcdTimeout =
            std::chrono::milliseconds(static_cast<int>(number(optarg, "pcd-timeout", 200, 2000)));
        break;
      case kDuration:
        duration = number(optarg, "duration", 0, 1e7);
        break;
      case kScene:
        if (std::string(optarg) == "static")
          scene.carFixed = true;
        else if (std::string(optarg) != "follow")
          usageError("--scene is follow or static");
        break;
      case kClockStamp:
        scene.clockStamp = true;
        break;
      case kFrames:
        framesDir = optarg;
        break;
      case kReplay:
        replayPath = optarg;
        break;
      case kCamera:
        replay.camera = optarg;
        break;
      case kSpeed:
        replay.options.speed = number(optarg, "speed", 0.01, 100);
        break;
      case kLoop:
        replay.options.loop = true;
        break;
      case kCommandsOut:
        replay.options.commandsOut = optarg;
        break;
      case kFamily:
        scene.family = optarg;
        break;
      case kTags:
        scene.tagIds = idList(optarg);
        break;
      case kTagSize:
        scene.tagSize = number(optarg, "tag-size", 0.01, 10);
        break;
      case kPath: {
        auto path = sim::parseTargetPath(optarg);
        if (!path) usageError(path.error());
        scene.path = *path;
        break;
      }
      case kTargetSpeed:
        scene.targetSpeed = number(optarg, "target-speed", 0, 10);
        break;
      case kStartDistance:
        scene.startDistance = number(optarg, "start-distance", 0.2, 100);
        break;
      case kFollowDistance:
        scene.followDistance = number(optarg, "follow-distance", 0.1, 100);
        break;
      case kSteeringChannel:
        scene.steeringChannel = static_cast<int>(number(optarg, "steering-channel", 1, 8));
        break;
      case kThrottleChannel:
        scene.throttleChannel = static_cast<int>(number(optarg, "throttle-channel", 1, 8));
        break;
      case kTruth:
        truthPath = optarg;
        break;
      case kControl:
        control = optarg;
        if (control != "wirc" && control != "rcoip" && control != "btemp")
          usageError("--control is wirc, rcoip or btemp");
        break;
      case kControlPort:
        controlPort = static_cast<uint16_t>(number(optarg, "control-port", 0, 65535));
        break;
      case kLoss:
        device.impairments.loss = number(optarg, "loss", 0, 1);
        break;
      case kBurstLoss:
        device.impairments.burstLoss = number(optarg, "burst-loss", 0, 1);
        break;
      case kBurstLength:
        device.impairments.burstLength = static_cast<int>(number(optarg, "burst-length", 1, 10000));
        break;
      case kDuplicate:
        device.impairments.duplication = number(optarg, "duplicate", 0, 1);
        break;
      case kReorder:
        device.impairments.reorderDepth = static_cast<int>(number(optarg, "reorder", 0, 1000));
        break;
      case kJitter:
        device.impairments.fragmentJitter = static_cast<size_t>(number(optarg, "jitter", 0, 65000));
        break;
      case kStartFrame:
        device.impairments.startFrameNumber =
            static_cast<uint32_t>(number(optarg, "start-frame", 0, 4294967295.0));
        break;
      case kReservedBits:
        device.impairments.reservedBits = true;
        break;
      case kStray:
        device.impairments.strayRate = number(optarg, "stray", 0, 1);
        break;
      case kMisdirect:
        device.impairments.misdirectPort =
            static_cast<uint16_t>(number(optarg, "misdirect", 1, 65535));
        break;
      case kSeed:
        device.impairments.seed = static_cast<uint32_t>(number(optarg, "seed", 0, 4294967295.0));
        break;
      case kMarvelmind:
        dashboardConfig().port = static_cast<uint16_t>(number(optarg, "marvelmind", 0, 65535));
        dashboardPort = true;
        break;
      case kMarvelmindBeacons: {
        auto beacons = marvelmind::parseBeacons(optarg);
        if (!beacons) usageError("--marvelmind-beacons: " + beacons.error());
        dashboardConfig().beacons = *beacons;
        break;
      }
      case kMarvelmindRate:
        dashboardConfig().rate = number(optarg, "marvelmind-rate", 0.1, 100);
        break;
      case kMarvelmindNoise:
        dashboardConfig().noise = number(optarg, "marvelmind-noise", 0, 10);
        break;
      case kMarvelmindDropout:
        dashboardConfig().dropout = number(optarg, "marvelmind-dropout", 0, 1);
        break;
      case kMarvelmindPush: {
        std::string text = optarg;
        auto colon = text.rfind(':');
        auto port = number(colon == std::string::npos ? "" : optarg + colon + 1, "marvelmind-push",
                           1, 65535);
        auto address = SocketAddress::resolve(text.substr(0, colon), static_cast<uint16_t>(port));
        if (!address) usageError("--marvelmind-push: " + address.error());
        dashboardConfig().pushTo = *address;
        break;
      }
      case kMarvelmindPushUnits:
        if (std::string(optarg) != "cm" && std::string(optarg) != "mm")
          usageError("--marvelmind-push-units is cm or mm");
        dashboardConfig().pushResolution = std::string(optarg) == "mm"
                                               ? marvelmind::Resolution::kMillimetres
                                               : marvelmind::Resolution::kCentimetres;
        break;
      case kMarvelmindTimestamp:
        if (std::string(optarg) != "64" && std::string(optarg) != "ms")
          usageError("--marvelmind-timestamp is 64 (1/64 s) or ms");
        dashboardConfig().timestampUnit = std::string(optarg) == "ms"
                                              ? marvelmind::TimestampUnit::kMilliseconds
                                              : marvelmind::TimestampUnit::kSixtyFourths;
        break;
      default:
        usageError("unknown option");
    }
  }
  if (optind < argc) usageError(std::string("unexpected argument '") + argv[optind] + "'");
  if (device.serial.size() > wirc::kSerialWidth) usageError("--serial is at most 7 characters");
  if (device.name.size() > wirc::kNameWidth) usageError("--name is at most 64 characters");
  if (dashboard && !dashboardPort) usageError("the --marvelmind-* options need --marvelmind PORT");

  if (framesDir && replayPath) usageError("--frames and --replay: one scene at a time");
  if (!replayPath && (!replay.camera.empty() || replay.options.loop || replay.options.speed != 1 ||
                      !replay.options.commandsOut.empty()))
    usageError("--camera, --speed, --loop and --commands-out go with --replay");

  // Signals are taken synchronously below; block them before any thread
  // starts. SIGUSR1: the replay has ended.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGUSR1);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  auto logger = [](const std::string& line) {
    std::fprintf(stderr, "%s wirc-sim: %s\n", timestamp().c_str(), line.c_str());
  };

  std::shared_ptr<wirc::DeviceScene> deviceScene;
  sim::FollowScene* follow = nullptr;
  sim::ReplayScene* replayed = nullptr;
  if (replayPath) {
    gst_init(&argc, &argv);
    auto drive = sim::RecordedDrive::open(*replayPath, replay.camera);
    if (!drive) {
      std::fprintf(stderr, "wirc-sim: %s\n", drive.error().c_str());
      return 1;
    }
    replay.options.log = logger;
    replay.options.ended = [] { kill(getpid(), SIGUSR1); };
    auto created = sim::ReplayScene::create(std::move(*drive), replay.options);
    if (!created) {
      std::fprintf(stderr, "wirc-sim: %s\n", created.error().c_str());
      return 1;
    }
    replayed = created->get();
    deviceScene = std::move(*created);
  } else if (framesDir) {
    auto frames = sim::JpegSequenceScene::loadFolder(*framesDir);
    if (!frames) usageError(frames.error());
    deviceScene = std::make_shared<sim::JpegSequenceScene>(std::move(*frames));
  } else {
    auto created = sim::FollowScene::create(scene);
    if (!created) usageError(created.error());
    follow = created->get();
    if (truthPath) {
      if (auto error = follow->writeTruthTo(*truthPath)) usageError(*error);
    }
    deviceScene = std::move(*created);
  }

  auto vehicle = sim::startVehicleControl(control, device.bindAddress, controlPort, logger);
  if (!vehicle) {
    std::fprintf(stderr, "wirc-sim: %s\n", vehicle.error().c_str());
    return 1;
  }
  if (*vehicle) {
    device.carControl = [control = vehicle->get()](wirc::DeviceClock::time_point now) {
      return control->outputs(now);
    };
  }
  auto started = wirc::Device::start(device, deviceScene, logger);
  if (!started) {
    std::fprintf(stderr, "wirc-sim: %s\n", started.error().c_str());
    return 1;
  }
  auto& sim = *started;
  std::printf("wirc-sim: listening on %s:%u\n", device.bindAddress.c_str(), sim->port());
  if (*vehicle)
    std::printf("wirc-sim: %s on %s:%u\n", (*vehicle)->description().c_str(),
                device.bindAddress.c_str(), (*vehicle)->port());
  std::unique_ptr<sim::MarvelmindDashboard> positions;
  if (dashboard) {
    dashboard->bindAddress = device.bindAddress;
    dashboard->seed = device.impairments.seed;
    auto running = sim::MarvelmindDashboard::start(*dashboard, beaconTruth(follow));
    if (!running) {
      std::fprintf(stderr, "wirc-sim: %s\n", running.error().c_str());
      return 1;
    }
    positions = std::move(*running);
    std::printf("wirc-sim: Marvelmind dashboard on %s:%u\n", device.bindAddress.c_str(),
                positions->port());
  }
  std::fflush(stdout);

  int caught = waitForStop(signals, duration);
  sim->stop();
  std::string dashboardSummary = positions ? positions->summary() : "";
  positions.reset();

  auto stats = sim->stats();
  const char* ending = caught == SIGUSR1 ? " (the replay ended)"
                       : caught > 0      ? " (stopped by signal)"
                                         : "";
  std::printf("wirc-sim summary:%s\n", ending);
  if (replayed) std::printf("  %s\n", replayed->summary().c_str());
  std::printf("  frames sent        %llu (%llu datagrams)\n",
              static_cast<unsigned long long>(stats.framesSent),
              static_cast<unsigned long long>(stats.datagramsSent));
  std::printf("  logins             %llu\n", static_cast<unsigned long long>(stats.logins));
  std::printf("  PCD received       %llu (%llu rejected)\n",
              static_cast<unsigned long long>(stats.pcdReceived),
              static_cast<unsigned long long>(stats.pcdRejected));
  std::printf("  max PCD gap        %lld ms\n", static_cast<long long>(stats.maxPcdGap.count()));
  std::printf("  failsafe entries   %llu\n",
              static_cast<unsigned long long>(stats.failsafeEntries));
  std::printf("  ERR sent           %llu\n", static_cast<unsigned long long>(stats.errSent));
  if (*vehicle) std::printf("  %s\n", (*vehicle)->summary().c_str());
  if (dashboard) std::printf("  %s\n", dashboardSummary.c_str());
  if (follow) {
    auto s = follow->summary();
    std::printf(
        "  following error    bearing mean %.2f° max %.2f°, distance mean %.3f m max %.3f m"
        " (after the first 3 s, %llu frames)\n",
        s.meanBearingDeg, s.maxBearingDeg, s.meanDistanceError, s.maxDistanceError,
        static_cast<unsigned long long>(s.measuredTicks));
  }
  return 0;
}
