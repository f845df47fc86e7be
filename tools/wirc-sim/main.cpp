// wirc-sim: a complete WiRC device on this machine, for tests, demos and
// benchmarks. See --help.
#include <gst/gst.h>
#include <signal.h>
#include <sys/resource.h>
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
#include "sim_options.h"
#include "vehicle_control.h"

using namespace wircam;

namespace {

constexpr int kReplayNice = -10;

[[noreturn]] void usageError(const std::string& message) {
  std::fprintf(stderr, "wirc-sim: %s (see wirc-sim --help)\n", message.c_str());
  std::exit(2);
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
  auto parsed = sim::parseSimOptions(argc, argv);
  if (!parsed) usageError(parsed.error());
  if (!*parsed) {
    std::fputs(sim::simUsage().c_str(), stdout);
    return 0;
  }
  sim::SimOptions& o = **parsed;
  auto& device = o.device;

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
  if (o.replayPath) {
    // A replay is a measurement of timing: each frame at its recorded time.
    // On a machine busy with the recorder, detection or anything else, its
    // threads (made from this one, so of its priority) wake ahead of that
    // work where allowed (CAP_SYS_NICE or RLIMIT_NICE), as the recorder's
    // link loop does; elsewhere they keep the process's priority.
    setpriority(PRIO_PROCESS, 0, kReplayNice);
    gst_init(&argc, &argv);
    auto drive = sim::RecordedDrive::open(*o.replayPath, o.replayCamera);
    if (!drive) {
      std::fprintf(stderr, "wirc-sim: %s\n", drive.error().c_str());
      return 1;
    }
    o.replay.log = logger;
    o.replay.ended = [] { kill(getpid(), SIGUSR1); };
    auto created = sim::ReplayScene::create(std::move(*drive), o.replay);
    if (!created) {
      std::fprintf(stderr, "wirc-sim: %s\n", created.error().c_str());
      return 1;
    }
    replayed = created->get();
    deviceScene = std::move(*created);
  } else if (o.framesDir) {
    auto frames = sim::JpegSequenceScene::loadFolder(*o.framesDir);
    if (!frames) usageError(frames.error());
    deviceScene = std::make_shared<sim::JpegSequenceScene>(std::move(*frames));
  } else {
    auto created = sim::FollowScene::create(o.scene);
    if (!created) usageError(created.error());
    follow = created->get();
    if (o.truthPath) {
      if (auto error = follow->writeTruthTo(*o.truthPath)) usageError(*error);
    }
    deviceScene = std::move(*created);
  }

  auto vehicle = sim::startVehicleControl(o.control, device.bindAddress, o.controlPort, logger);
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
  if (o.dashboard) {
    o.dashboard->bindAddress = device.bindAddress;
    o.dashboard->seed = device.impairments.seed;
    auto running = sim::MarvelmindDashboard::start(*o.dashboard, beaconTruth(follow));
    if (!running) {
      std::fprintf(stderr, "wirc-sim: %s\n", running.error().c_str());
      return 1;
    }
    positions = std::move(*running);
    std::printf("wirc-sim: Marvelmind dashboard on %s:%u\n", device.bindAddress.c_str(),
                positions->port());
  }
  std::fflush(stdout);

  int caught = waitForStop(signals, o.duration);
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
  std::printf("  max frame tick gap %lld ms\n", static_cast<long long>(stats.maxTickGap.count()));
  std::printf("  failsafe entries   %llu\n",
              static_cast<unsigned long long>(stats.failsafeEntries));
  std::printf("  ERR sent           %llu\n", static_cast<unsigned long long>(stats.errSent));
  if (*vehicle) std::printf("  %s\n", (*vehicle)->summary().c_str());
  if (o.dashboard) std::printf("  %s\n", dashboardSummary.c_str());
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
