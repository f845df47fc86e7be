// One wirc-recorder run: a pipeline per camera (pipeline_plan.h), their
// buses turned into telemetry (sidecar and text track), the status display,
// the disk guard, and the web and RTSP servers when asked for. A camera's
// EOS, error or silence is its own: the others record on, and a stop
// finishes every camera that has frames within kFinishTime, cutting off (and
// naming) any that cannot.
#pragma once

#include <gst/gst.h>

#include <deque>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "common/expected.h"
#include "disk_guard.h"
#include "fleet_publisher.h"
#include "frame_tap.h"
#include "http_server.h"
#include "pipeline_plan.h"
#include "recorder_options.h"
#include "recording_index.h"
#include "retention.h"
#include "rtsp_server.h"
#include "segment_hook.h"
#include "segment_planner.h"
#include "segment_splitter.h"
#include "telemetry_router.h"
#include "telemetry_track.h"

namespace wircam::recorder {

// Exit codes besides 0 (finished) and 2 (bad arguments, in main).
inline constexpr int kExitError = 1;
inline constexpr int kExitDiskFull = 3;

class Recording {
 public:
  // How long a stop waits for the cameras to finish their files: the
  // process ends within 3 s of it, whatever a camera or device does.
  static constexpr guint kFinishTimeMs = 2500;

  static Expected<std::unique_ptr<Recording>, std::string> create(const RecorderOptions& options);
  ~Recording();

  // Records until SIGINT/SIGTERM, --duration, a full disk or an error;
  // every file is finished before it returns. The process exit code.
  int run();

 private:
  struct Stream {
    StreamPlan plan;
    GstElement* pipeline = nullptr;  // this camera's alone
    bool ended = false;              // reached EOS, or was stopped (an error, the stop's deadline)
    std::unique_ptr<SegmentPlanner> planner;
    std::optional<TelemetryTrack> track;
    std::unique_ptr<TelemetryRouter> telemetry;
    std::unique_ptr<SegmentSplitter> splitter;
    std::unique_ptr<FrameTap> frames;  // with --http or --rtsp
    std::string segment;               // the file being written
    guint64 frameCount = 0, incomplete = 0, bytes = 0;
    GstClockTime statsTime = GST_CLOCK_TIME_NONE;  // of the last wirc-stats
    double fps = 0, kbps = 0;
    guint batteryMv = 0;
    bool statusStale = false;  // the device stopped reporting; batteryMv is its last word
    guint64 statusAgeMs = 0;
    // The vehicle's latest Marvelmind position, with --marvelmind.
    struct Position {
      guint beacon = 0;
      double x = 0, y = 0, z = 0;
      int64_t unixMs = 0;
    };
    std::optional<Position> position;
    std::string positionStale;   // why, when no position came for a while
    std::deque<Position> trail;  // the recent ones, for the live view's map
    // "waiting for device" until the first login, then "live" or "offline".
    std::string state = "waiting for device";
    int64_t stateSinceUnixMs = 0;
    std::string linkReason;  // why the link is not live (a refusal, a loss), while it is not
  };

  explicit Recording(RecorderOptions options);
  std::optional<std::string> startServers();  // the problem, if any
  static gboolean onBusMessage(GstBus* bus, GstMessage* message, gpointer self);
  static gboolean onFinishDeadline(gpointer self);
  // Tears one camera's pipeline down (its open segment indexed as it is).
  void endStream(Stream& stream);
  // Ends the run once every camera has ended (all stopped, or all failed).
  void quitWhenAllEnded();
  static gboolean onStop(gpointer self);  // SIGINT, SIGTERM
  static gboolean onDurationOver(gpointer self);
  static gboolean onTick(gpointer self);
  static gboolean onHeartbeat(gpointer self);
  void stop(const char* why);
  void handleElementMessage(GstMessage* message);
  void handleError(GstMessage* message);
  void handlePosition(Stream& stream, const GstStructure* s);
  // MQTT: a stream's status as the fleet sees it, and a command for it.
  nlohmann::json fleetStatus(const Stream& stream) const;
  // What the stream's wirccontrol says (all off without --follow).
  struct Control {
    bool hasControl = false, following = false;
    int target = -1;
  };
  Control controlOf(const Stream& stream) const;
  // The latest Marvelmind position (null until one came), for status and MQTT.
  nlohmann::json positionJson(const Stream& stream) const;
  // DELETE /api/recordings/FILE: the HTTP status and reason when it cannot.
  std::optional<std::pair<guint, std::string>> deleteSegment(const std::string& file);
  void publishFleetStatus(bool force = false);
  // Why it cannot be carried out (the stream does not follow), if so.
  // `from` says where it came from in the log: "MQTT", "web".
  std::optional<std::string> applyCommand(const FleetCommand& command, const char* from);
  // Drive mode from the web page: whether the vehicle obeys, or nullopt
  // when the stream has no wirccontrol.
  std::optional<bool> drive(const std::string& stream, double steering, double throttle);
  void publishEvent(const Stream& stream, const nlohmann::json& event);
  GstElement* element(const std::string& name) const;
  void writeTelemetry(Stream& stream, nlohmann::json line, GstClockTime runningTime);
  void onSegmentClosed(Stream& stream, const std::string& file);
  void followLinkState(Stream& stream, const std::string& linkState, const std::string& reason);
  void updateIndex(const std::vector<std::string>& deleted);
  GstClockTime runningTime(const Stream& stream) const;
  void printStatus();
  void guardDisk();
  nlohmann::json status() const;
  nlohmann::json trails() const;
  std::vector<std::string> openSegments() const;
  Stream* streamOf(GstMessage* message);
  Stream* streamOfPipeline(GstObject* pipeline);
  Stream* streamNamed(const std::string& name);

  RecorderOptions options_;
  Retention retention_;
  DiskGuard disk_;
  RecordingIndex index_;
  GMainLoop* loop_ = nullptr;
  std::vector<std::unique_ptr<Stream>> streams_;
  std::map<std::string, Stream*> streamByElement_;  // element name → its stream
  std::unique_ptr<HttpServer> http_;
  std::unique_ptr<RtspServer> rtsp_;
  std::unique_ptr<FleetPublisher> fleet_;  // with --mqtt
  std::unique_ptr<SegmentHook> hook_;      // with --on-segment-closed
  std::vector<guint> timers_;              // the run's timeouts, removed when it ends
  bool stopping_ = false;
  bool stoppedBySignal_ = false;
  int exitCode_ = 0;
  bool statusShown_ = false;
};

}  // namespace wircam::recorder
