// One recorded camera under the supervisor: its pipeline (a new one after
// each fault), its health, and what its elements say on their bus, turned
// into its report, its telemetry and its events. Everything here runs on
// the main loop, except the frames, which the pipeline's threads carry.
//
// A fault (a pipeline error, no video for the stall timeout, the device
// lost while a file is open) closes the camera's open file at its last
// frame (EOS, bounded by CameraMachine::kFinishTime), tears its pipeline down and starts a
// new one after CameraHealth's backoff; a build that fails is tried again
// after the next backoff. CameraMachine decides all of it; this class is its
// driver (the pipeline, its bus, one timer). No other camera waits for any
// of it.
#pragma once

#include <gst/gst.h>

#include <chrono>
#include <deque>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "camera/bus_watch.h"
#include "camera/camera_health.h"
#include "camera/camera_machine.h"
#include "camera/camera_pipeline.h"
#include "camera/frame_tap.h"
#include "camera/pipeline_plan.h"
#include "status/camera_report.h"
#include "wirc_bus_messages.h"

namespace wircam::recorder {

class Camera;

// What a camera tells the supervisor.
class CameraObserver {
 public:
  virtual ~CameraObserver() = default;
  // A file of the camera is finished (or cut off as it is): index it.
  virtual void segmentClosed(Camera& camera, const std::string& file,
                             const PlannedSegment& planned) = 0;
  // A link change, a command, a segment: for MQTT's events.
  virtual void event(Camera& camera, const nlohmann::json& event) = 0;
  // A frame's detections, for the live view and MQTT.
  virtual void detections(Camera& camera, const nlohmann::json& line, int64_t unixMs,
                          GstClockTime framePts) = 0;
  // A write failed for want of space: the recording must stop.
  virtual void diskFull(Camera& camera) = 0;
  // The camera stopped for good (after stop()).
  virtual void ended(Camera& camera) = 0;
};

class Camera {
 public:
  // Builds a run's pipeline (CameraPipeline::build; a test's may fail).
  using PipelineBuilder = std::function<Expected<std::unique_ptr<CameraPipeline>, std::string>(
      const StreamPlan&, const CameraFiles&, FrameTap* frames, FrameTap* encoded)>;

  // Builds its first pipeline (a bad description is an error here, not a
  // fault later). `liveFrames`: keep a FrameTap for the live outputs.
  static Expected<std::unique_ptr<Camera>, std::string> create(
      StreamPlan plan, CameraFiles files, CameraHealth::Policy policy, CameraObserver& observer,
      PipelineBuilder build = CameraPipeline::build);
  ~Camera();
  Camera(const Camera&) = delete;
  Camera& operator=(const Camera&) = delete;

  // The first start; false if its pipeline could not even start (the
  // error is logged). Later starts after faults are the camera's own.
  bool start();
  // Called every kTickInterval: the stall check, state changes.
  void tick();
  static constexpr guint kTickIntervalMs = 250;
  // New settings (a reload): the open file finished, then a pipeline built
  // with them at once. Its frame taps stay: the live servers keep their feed.
  void replan(StreamPlan plan, CameraFiles files, CameraHealth::Policy policy);
  // What it was last given (a reload compares them).
  const CameraFiles& files() const { return nextFiles_ ? *nextFiles_ : files_; }
  const StreamPlan& plannedNext() const { return nextPlan_ ? *nextPlan_ : plan_; }
  const CameraHealth::Policy& policy() const { return policy_; }
  // Finishes the open file (bounded by CameraMachine::kFinishTime) and stops for good.
  void stop();
  // Stops for good at once, the open file indexed as it is (a second
  // signal, the stop's backstop).
  void halt();
  bool ended() const { return machine_.phase() == CameraPhase::kEnded; }
  CameraPhase phase() const { return machine_.phase(); }
  bool hasFrames() const { return pipeline_ && pipeline_->hasFrames(); }
  // Whether any run of it has recorded a frame.
  bool recordedAny() const { return filesClosed_ > 0 || hasFrames(); }

  const StreamPlan& plan() const { return plan_; }
  const std::string& name() const { return plan_.name; }
  FrameTap* frames() { return plan_.liveSink.empty() ? nullptr : &frames_; }
  // The recording's own H.264 frames (--codec h264, with live outputs), or null.
  FrameTap* encodedFrames() {
    return plan_.liveSink.empty() || !files_.transcoded ? nullptr : &encodedFrames_;
  }
  // The wirccontrol of the running pipeline, or null (none, or restarting).
  GstElement* controller() const;
  CameraReport report() const;
  const std::deque<Position>& trail() const { return trail_; }
  bool positionStale() const { return !report_.positionStale.empty(); }
  const std::string& openSegment() const { return report_.segment; }
  // Every file of the running pipeline not finished yet: the one being
  // written, and the one before it while its muxer still writes its end.
  std::vector<std::string> unfinishedSegments() const;
  double kbps() const { return report_.kbps; }
  // A line of the camera's telemetry, now (a command, say).
  void writeTelemetry(const nlohmann::json& line);

 private:
  Camera(StreamPlan plan, CameraFiles files, CameraHealth::Policy policy, CameraObserver& observer,
         PipelineBuilder build);

  static gboolean onBusMessage(GstBus* bus, GstMessage* message, gpointer self);
  void watchBus();
  void handleElementMessage(GstMessage* message);  // camera_messages.cpp
  void handleSession(const GstStructure* s, nlohmann::json line);
  void handleStats(const GstStructure* s, nlohmann::json line);
  void handlePosition(const GstStructure* s);
  void handleError(GstMessage* message);
  void writeTelemetry(nlohmann::json line, GstClockTime runningTime);
  // Tells the observer a file is done, as its planner knew it.
  void closed(const std::string& file);
  // Does what the machine says, then arms the timer for its next deadline.
  void apply(CameraActions actions);
  void endFile(bool forGood);
  // Tears the pipeline down, its open files indexed as they are.
  void tearDown();
  void rebuild();
  static gboolean onDeadline(gpointer self);
  bool play();
  void publishState();
  // The frames dropped for the disk: into the report, and the log.
  void reportDrops();
  // The source's last counts into the report, before its pipeline goes.
  void keepFinalCounts();
  // The source's counters now (updated at each frame), while it is there.
  std::optional<bus::Stats> sourceStatsNow() const;
  // Raises `report`'s counts to what `stats` say of this run.
  void countFrom(const bus::Stats& stats, CameraReport& report) const;

  StreamPlan plan_;
  CameraFiles files_;
  // A reload's, taken at the next build.
  std::optional<StreamPlan> nextPlan_;
  std::optional<CameraFiles> nextFiles_;
  CameraHealth::Policy policy_;
  CameraObserver& observer_;
  CameraMachine machine_;
  PipelineBuilder build_;
  FrameTap frames_;
  FrameTap encodedFrames_;
  std::unique_ptr<CameraPipeline> pipeline_;
  std::unique_ptr<BusWatch> busWatch_;
  guint deadlineTimer_ = 0;  // at machine_.nextDeadline()
  uint64_t filesClosed_ = 0;
  uint64_t framesSeen_ = 0;      // the frames that came for the files, at the last tick
  uint64_t earlierDropped_ = 0;  // for the disk, in past runs
  std::optional<CameraHealth::Clock::time_point> dropLogged_;
  GstClockTime statsTime_ = GST_CLOCK_TIME_NONE;  // of the last wirc-stats
  bool everLive_ = false;                         // logged in at least once
  struct Counts {
    uint64_t frames = 0, incomplete = 0, bytes = 0, commandsSent = 0;
  };
  Counts earlierRuns_, runCounts_;  // the sources' counts: past pipelines', this one's
  std::optional<std::pair<bool, int>> carriedControl_;
  std::deque<TelemetryRouter::Line>
      carriedTelemetry_;  // for the next run's first file  // following, target: for the next run
  CameraReport report_;
  std::deque<Position> trail_;  // the recent positions, for the live view's map
};

}  // namespace wircam::recorder
