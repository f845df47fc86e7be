// One wirc-recorder run: the supervisor of its cameras (each a pipeline of
// its own, camera/camera.h), and what they share: the index and retention,
// the disk guard, the status display, the web, RTSP and MQTT servers, the
// segment hook. A camera's fault, silence or stall is its own; a stop ends
// every camera within CameraMachine::kFinishTime, cutting off (and naming) any
// that cannot finish.
#pragma once

#include <gst/gst.h>

#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "app/command_dispatcher.h"
#include "app/recorder_options.h"
#include "camera/camera.h"
#include "common/expected.h"
#include "fleet/fleet_publisher.h"
#include "live/live_servers.h"
#include "record/disk_guard.h"
#include "record/recording_index.h"
#include "record/retention.h"
#include "record/segment_hook.h"
#include "status/prometheus_metrics.h"

namespace wircam::recorder {

// Exit codes besides 0 (finished) and 2 (bad arguments, in main).
inline constexpr int kExitError = 1;
inline constexpr int kExitDiskFull = 3;

class Supervisor : CameraObserver {
 public:
  static Expected<std::unique_ptr<Supervisor>, std::string> create(const RecorderOptions& options);
  ~Supervisor() override;

  // Records until SIGINT/SIGTERM, --duration, a full disk or an error;
  // every file is finished (or cut off) before it returns. The exit code.
  int run();

 private:
  explicit Supervisor(RecorderOptions options);
  std::optional<std::string> startServers();  // the problem, if any

  // CameraObserver
  void segmentClosed(Camera& camera, const std::string& file,
                     const PlannedSegment& planned) override;
  void event(Camera& camera, const nlohmann::json& event) override;
  void detections(Camera& camera, const nlohmann::json& line, int64_t unixMs,
                  GstClockTime framePts) override;
  void diskFull(Camera& camera) override;
  void ended(Camera& camera) override;

  void stop(const char* why);
  static gboolean onStopDeadline(gpointer self);
  static gboolean onSignal(gpointer self);  // SIGINT, SIGTERM
  static gboolean onDurationOver(gpointer self);
  static gboolean onTick(gpointer self);
  static gboolean onCameraTick(gpointer self);
  void quitWhenAllEnded();
  void publishFleetStatus(bool force = false);
  void publishFoxgloveStatus();  // each camera's /STREAM/telemetry, once a second
  void publishFoxglovePoses();   // each new position on /STREAM/pose
  // DELETE /api/recordings/FILE: the HTTP status and reason when it cannot.
  std::optional<std::pair<guint, std::string>> deleteSegment(const std::string& file);
  void updateIndex(const std::vector<std::string>& deleted);
  void enforceRetention();  // and the index after it
  void publishSnapshots();  // --mqtt-discovery's camera entity
  void printStatus();
  void guardDisk();
  std::string rtspOf(const Camera& camera) const;
  nlohmann::json status() const;
  std::string metrics() const;  // GET /metrics
  nlohmann::json trails() const;
  std::vector<std::string> openSegments() const;
  Camera* cameraNamed(const std::string& name);

  RecorderOptions options_;
  Retention retention_;
  DiskGuard disk_;
  RecordingIndex index_;
  std::map<std::string, RecordedTotals> recorded_;  // by camera, since the start
  GMainLoop* loop_ = nullptr;
  std::vector<std::unique_ptr<Camera>> cameras_;
  CommandDispatcher commands_;
  std::unique_ptr<WebServer> http_;            // with --http
  std::unique_ptr<RtspService> rtsp_;          // with --rtsp
  std::unique_ptr<FleetPublisher> fleet_;      // with --mqtt
  std::unique_ptr<FoxgloveService> foxglove_;  // with --foxglove
  std::map<std::string, int64_t> posesSent_;   // by camera: the last position's time
  std::unique_ptr<SegmentHook> hook_;          // with --on-segment-closed
  std::vector<guint> timers_;                  // the run's timeouts, removed when it ends
  bool stopping_ = false;
  bool stoppedBySignal_ = false;
  int exitCode_ = 0;
  bool statusShown_ = false;
};

}  // namespace wircam::recorder
