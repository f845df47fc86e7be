// One wirc-recorder run: the supervisor of its cameras (each a pipeline of
// its own, camera/camera.h), and what they share: the index and retention,
// the disk guard, the status display, the web, RTSP and MQTT servers, the
// segment hook. A camera's fault, silence or stall is its own; a stop ends
// every camera within CameraMachine::kFinishTime, cutting off (and naming) any
// that cannot finish.
#pragma once

#include <gst/gst.h>

#include <functional>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "app/command_dispatcher.h"
#include "app/recorder_options.h"
#include "app/run_schedule.h"
#include "camera/camera.h"
#include "common/expected.h"
#include "fleet/fleet_publisher.h"
#include "fleet/vehicle_identity.h"
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
  // The options as a reload reads them again (the command line re-parsed,
  // with the config file's present text).
  using Reread = std::function<Expected<RecorderOptions, std::string>()>;
  static Expected<std::unique_ptr<Supervisor>, std::string> create(const RecorderOptions& options,
                                                                   Reread reread = nullptr);
  ~Supervisor() override;

  // Records until SIGINT/SIGTERM, --duration, a full disk or an error;
  // every file is finished (or cut off) before it returns. The exit code.
  int run();

  // SIGHUP, POST /api/config/reload (supervisor_reload.cpp): the cameras
  // added, removed, restarted and unchanged, or why nothing changed.
  Expected<nlohmann::json, std::string> reload();

 private:
  Supervisor(RecorderOptions options, Reread reread);
  std::optional<std::string> startServers();  // the problem, if any
  // What the options make of each camera: its files and health policy.
  static CameraFiles filesOf(const RecorderOptions& options, const PipelinePlan& plan);
  static CameraHealth::Policy healthOf(const RecorderOptions& options);
  static RetentionLimits retentionOf(const RecorderOptions& options);
  // --detect FAMILY against the families apriltagdetect knows.
  static std::optional<std::string> checkFamily(const std::string& family);
  // A camera a reload removed: out of the servers, its file finished, then
  // forgotten once it has ended.
  void removeCamera(Camera& camera);
  void forgetEndedCameras();
  void addToServers(Camera& camera);
  void removeFromServers(Camera& camera);
  static gboolean onReloadSignal(gpointer self);  // SIGHUP

  // CameraObserver
  void segmentClosed(Camera& camera, const std::string& file,
                     const PlannedSegment& planned) override;
  void event(Camera& camera, const nlohmann::json& event) override;
  void detections(Camera& camera, const nlohmann::json& line, int64_t unixMs,
                  GstClockTime framePts) override;
  void diskFull(Camera& camera) override;
  void ended(Camera& camera) override;

  void stop(const char* why);
  static gboolean onSignal(gpointer self);  // SIGINT, SIGTERM
  void armSchedule();
  static gboolean onSchedule(gpointer self);
  void perform(RunJob job);  // one job of the schedule
  void quitWhenAllEnded();
  void publishFleetStatus(bool force = false);
  // The fleet (supervisor_fleet.cpp): a live device is asked who its
  // vehicle is; the announcement says this recorder, its addresses and its
  // cameras' vehicles, on change and every kAnnounceIntervalMs (when it was
  // last seen, for a fleet that finds it offline).
  static constexpr int64_t kAnnounceIntervalMs = 30000;
  void identify(Camera& camera);
  void announce();
  nlohmann::json withVehicle(nlohmann::json entry, const Camera& camera) const;
  void publishFoxgloveStatus();  // each camera's /STREAM/telemetry, once a second
  void publishFoxglovePoses();   // each new position on /STREAM/pose
  // DELETE /api/recordings/FILE: the HTTP status and reason when it cannot.
  std::optional<std::pair<guint, std::string>> deleteSegment(const std::string& file);
  void updateIndex(const std::vector<std::string>& deleted);
  void enforceRetention();  // and the index after it
  // index.json written once the main loop is idle: many segments closing
  // at once (a stop of hundreds of cameras) write it once, not once each,
  // which kept the loop from the cameras' ends until they were cut off.
  // Deletions are written at once (the files are gone).
  void saveIndexSoon();
  void saveIndexNow();
  static gboolean onSaveIndex(gpointer self);
  void publishSnapshots();  // --mqtt-discovery's camera entity
  void printStatus();
  void guardDisk();
  std::string rtspOf(const Camera& camera) const;
  nlohmann::json status() const;
  std::string metrics() const;  // GET /metrics
  nlohmann::json trails() const;
  std::vector<std::string> openSegments() const;
  Camera* cameraNamed(const std::string& name);  // not one a reload removed
  std::vector<std::string> cameraNames() const;  // likewise

  RecorderOptions options_;
  Reread reread_;
  Retention retention_;
  DiskGuard disk_;
  RecordingIndex index_;
  guint indexSave_ = 0;  // saveIndexSoon()'s idle source, while one waits
  std::map<std::string, RecordedTotals> recorded_;  // by camera, since the start
  GMainLoop* loop_ = nullptr;
  std::vector<std::unique_ptr<Camera>> cameras_;
  std::set<Camera*> removing_;    // removed by a reload, finishing their file
  std::set<Camera*> startLater_;  // added again: started once their namesake has ended
  CommandDispatcher commands_;
  std::unique_ptr<WebServer> http_;            // with --http
  std::unique_ptr<RtspService> rtsp_;          // with --rtsp
  std::unique_ptr<FleetPublisher> fleet_;      // with --mqtt
  VehicleIdentities vehicles_;                 // by device label
  std::string recorderId_;                     // with --mqtt (fleet/recorder_id.h)
  int64_t announcedAt_ = 0;                    // monotonic ms
  std::unique_ptr<FoxgloveService> foxglove_;  // with --foxglove
  std::map<std::string, int64_t> posesSent_;   // by camera: the last position's time
  std::unique_ptr<SegmentHook> hook_;          // with --on-segment-closed
  std::optional<RunSchedule> schedule_;        // from run(): what it does on time
  guint scheduleTimer_ = 0;                    // armed to the schedule's next job
  std::vector<guint> timers_;                  // the run's signal sources, removed when it ends
  bool stopping_ = false;
  bool stoppedBySignal_ = false;
  int exitCode_ = 0;
  uint64_t segmentsThisRun_ = 0;  // closed since the recorder started
  bool statusShown_ = false;
};

}  // namespace wircam::recorder
