#include "camera/camera.h"

#include "log_line.h"
#include "wirc_bus_messages.h"

namespace wircam::recorder {

namespace {
CameraHealth::Clock::time_point now() { return CameraHealth::Clock::now(); }
int64_t unixMsNow() { return g_get_real_time() / 1000; }
}  // namespace

Camera::Camera(StreamPlan plan, CameraFiles files, CameraHealth::Policy policy,
               CameraObserver& observer, PipelineBuilder build)
    : plan_(std::move(plan)),
      files_(std::move(files)),
      policy_(policy),
      observer_(observer),
      machine_(policy, now()),
      build_(std::move(build)) {
  report_.name = plan_.name;
  report_.device = plan_.device;
  report_.camera = plan_.camera;
  report_.state = toString(machine_.health().state(now()));
  report_.stateSinceUnixMs = unixMsNow();
  report_.positions = !plan_.positions.empty();
}

Expected<std::unique_ptr<Camera>, std::string> Camera::create(StreamPlan plan, CameraFiles files,
                                                              CameraHealth::Policy policy,
                                                              CameraObserver& observer,
                                                              PipelineBuilder build) {
  std::unique_ptr<Camera> camera(
      new Camera(std::move(plan), std::move(files), policy, observer, std::move(build)));
  auto pipeline =
      camera->build_(camera->plan_, camera->files_, camera->frames(), camera->encodedFrames());
  if (!pipeline) return unexpected(pipeline.error());
  camera->pipeline_ = std::move(*pipeline);
  return camera;
}

Camera::~Camera() {
  if (deadlineTimer_) g_source_remove(deadlineTimer_);
  busWatch_.reset();
  pipeline_.reset();
}

void Camera::watchBus() {
  busWatch_.reset();  // (a bus takes one watch at a time)
  GstBus* bus = gst_element_get_bus(pipeline_->pipeline());
  busWatch_ = std::make_unique<BusWatch>(bus, onBusMessage, this);
  gst_object_unref(bus);
}

bool Camera::play() {
  watchBus();
  if (gst_element_set_state(pipeline_->pipeline(), GST_STATE_PLAYING) != GST_STATE_CHANGE_FAILURE)
    return true;
  // The error itself was posted: say it.
  if (GstMessage* message = busWatch_->take(GST_MESSAGE_ERROR)) {
    GError* error = nullptr;
    gst_message_parse_error(message, &error, nullptr);
    logLine(name() + ": cannot start: " + error->message);
    g_error_free(error);
    gst_message_unref(message);
  }
  return false;
}

bool Camera::start() { return play(); }

GstElement* Camera::controller() const {
  return pipeline_ ? pipeline_->element(plan_.controller) : nullptr;
}

void Camera::tick() {
  CameraActions actions;
  if (pipeline_ && machine_.phase() == CameraPhase::kRunning) {
    uint64_t frames = pipeline_->framesArrived();
    if (frames != framesSeen_) actions = machine_.frame(now());
    framesSeen_ = frames;
    reportDrops();
  }
  auto due = machine_.tick(hasFrames(), now());
  actions.insert(actions.end(), due.begin(), due.end());
  apply(std::move(actions));
}

void Camera::apply(CameraActions actions) {
  using Kind = CameraAction::Kind;
  for (auto& action : actions) {
    switch (action.kind) {
      case Kind::kEndFile:
        endFile(action.forGood);
        break;
      case Kind::kTearDown:
        tearDown();
        break;
      case Kind::kBuild:
        rebuild();  // applies what its outcome brings
        break;
      case Kind::kPublishState:
        publishState();
        break;
      case Kind::kEnded:
        observer_.ended(*this);
        break;
      case Kind::kLog:
        logLine(name() + ": " + action.text);
        break;
    }
  }
  // One timer, at the machine's next deadline (a finish cut off, a restart).
  if (deadlineTimer_) g_source_remove(std::exchange(deadlineTimer_, 0));
  if (auto deadline = machine_.nextDeadline()) {
    auto delay = std::chrono::duration_cast<std::chrono::milliseconds>(*deadline - now());
    deadlineTimer_ =
        g_timeout_add(static_cast<guint>(std::max<int64_t>(0, delay.count())), onDeadline, this);
  }
}

gboolean Camera::onDeadline(gpointer data) {
  auto* self = static_cast<Camera*>(data);
  self->deadlineTimer_ = 0;
  self->apply(self->machine_.tick(self->hasFrames(), now()));
  return G_SOURCE_REMOVE;
}

void Camera::publishState() {
  report_.state = toString(machine_.health().state(now()));
  report_.stateSinceUnixMs = unixMsNow();
  logLine(name() + ": " + report_.state +
          (report_.linkReason.empty() ? "" : " (" + report_.linkReason + ")"));
  observer_.event(*this, {{"type", "state"}, {"state", report_.state}});
}

void Camera::endFile(bool forGood) {
  if (!pipeline_) return;
  if (forGood) {
    // What waited for frames that will not come goes into the last file.
    pipeline_->telemetry().finish();
  } else {
    auto waiting = pipeline_->telemetry().handOver();
    carriedTelemetry_.insert(carriedTelemetry_.end(), std::make_move_iterator(waiting.begin()),
                             std::make_move_iterator(waiting.end()));
  }
  pipeline_->writer().end();
}

void Camera::tearDown() {
  busWatch_.reset();
  if (GstElement* control = controller()) {
    // What the user set (following, the target) carries over to the next run.
    gboolean enabled = FALSE;
    gint target = -1;
    g_object_get(control, "enabled", &enabled, "target-id", &target, nullptr);
    carriedControl_ = {enabled != FALSE, target};
  }
  if (pipeline_) {
    gst_element_set_state(pipeline_->pipeline(), GST_STATE_NULL);
    keepFinalCounts();
    // A file EOS did not finish is still playable (Matroska written in
    // clusters, fragmented MP4): indexed like any other.
    for (const auto& file : pipeline_->writer().unfinished()) closed(file);
    reportDrops();  // its last count, before it goes
  }
  report_.segment.clear();
  pipeline_.reset();
  framesSeen_ = 0;
  statsTime_ = GST_CLOCK_TIME_NONE;
  earlierRuns_.frames += runCounts_.frames;
  earlierRuns_.incomplete += runCounts_.incomplete;
  earlierRuns_.bytes += runCounts_.bytes;
  earlierRuns_.commandsSent += runCounts_.commandsSent;
  runCounts_ = {};
  earlierDropped_ = report_.recordingDropped;
}

void Camera::keepFinalCounts() {
  // Its once-a-second message may be most of a second old, and the
  // camera's last status line, printed once the source has gone, would
  // count fewer frames than its files hold.
  auto stats = sourceStatsNow();
  if (!stats) return;
  countFrom(*stats, report_);
  runCounts_.frames = report_.frames - earlierRuns_.frames;
  runCounts_.incomplete = report_.incomplete - earlierRuns_.incomplete;
  runCounts_.bytes = report_.bytes - earlierRuns_.bytes;
}

void Camera::reportDrops() {
  uint64_t dropped = earlierDropped_ + pipeline_->framesDropped();
  if (dropped == report_.recordingDropped) return;
  report_.recordingDropped = dropped;
  // Never silent, and not a line per frame: once, then every 10 s.
  auto at = now();
  if (dropLogged_ && at - *dropLogged_ < std::chrono::seconds(10)) return;
  dropLogged_ = at;
  logLine(name() + ": its file is behind (a slow or stalled disk): " + std::to_string(dropped) +
          " frame(s) dropped from the recording so far; the live view and following go on");
}

void Camera::replan(StreamPlan plan, CameraFiles files, CameraHealth::Policy policy) {
  nextPlan_ = std::move(plan);
  nextFiles_ = std::move(files);
  policy_ = policy;
  apply(machine_.replan(policy, hasFrames(), now()));
}

void Camera::rebuild() {
  if (nextPlan_) {
    plan_ = *std::exchange(nextPlan_, std::nullopt);
    files_ = *std::exchange(nextFiles_, std::nullopt);
    report_.positions = !plan_.positions.empty();
  }
  auto pipeline = build_(plan_, files_, frames(), encodedFrames());
  if (!pipeline) return apply(machine_.buildFailed(pipeline.error(), now()));
  pipeline_ = std::move(*pipeline);
  if (GstElement* control = controller(); control && carriedControl_)
    g_object_set(control, "enabled", carriedControl_->first ? TRUE : FALSE, "target-id",
                 carriedControl_->second, nullptr);
  // What the last run left waiting opens this run's first file.
  for (auto& line : std::exchange(carriedTelemetry_, {}))
    pipeline_->telemetry().write(std::move(line.json), 0, line.unixMs);
  apply(machine_.built(now()));
  report_.restarts = machine_.health().restarts();
  if (!play()) {
    logLine(name() + ": its pipeline did not start");
    apply(machine_.pipelineError(now()));
  }
}

void Camera::closed(const std::string& file) {
  auto planned = pipeline_ ? pipeline_->planner().segmentOf(file) : std::nullopt;
  ++filesClosed_;
  if (planned)
    observer_.segmentClosed(*this, file, *planned);
  else
    logLine(name() + ": " + file + " was not planned; not indexed");
}

void Camera::stop() { apply(machine_.stop(hasFrames(), now())); }

void Camera::halt() { apply(machine_.halt(now())); }

void Camera::handleError(GstMessage* message) {
  GError* error = nullptr;
  gchar* debug = nullptr;
  gst_message_parse_error(message, &error, &debug);
  bool diskFull = g_error_matches(error, GST_RESOURCE_ERROR, GST_RESOURCE_ERROR_NO_SPACE_LEFT);
  logLine(std::string(GST_OBJECT_NAME(GST_MESSAGE_SRC(message))) + ": " + error->message + "\n" +
          (debug ? debug : ""));
  g_error_free(error);
  g_free(debug);
  if (diskFull) {
    // This camera's file cannot be finished; the others may still be.
    observer_.diskFull(*this);
    return apply(machine_.diskFull(now()));
  }
  apply(machine_.pipelineError(now()));
}

gboolean Camera::onBusMessage(GstBus*, GstMessage* message, gpointer data) {
  auto* self = static_cast<Camera*>(data);
  switch (GST_MESSAGE_TYPE(message)) {
    case GST_MESSAGE_ELEMENT:
      self->handleElementMessage(message);
      break;
    case GST_MESSAGE_WARNING: {
      GError* error = nullptr;
      gchar* debug = nullptr;
      gst_message_parse_warning(message, &error, &debug);
      logLine(std::string("warning from ") + GST_OBJECT_NAME(GST_MESSAGE_SRC(message)) + ": " +
              error->message + " (" + (debug ? debug : "") + ")");
      g_error_free(error);
      g_free(debug);
      break;
    }
    case GST_MESSAGE_ERROR:
      self->handleError(message);
      return self->busWatch_ ? G_SOURCE_CONTINUE : G_SOURCE_REMOVE;
    case GST_MESSAGE_EOS:
      // Its files are finished (after a stop's or a fault's EOS).
      self->report_.segment.clear();
      self->apply(self->machine_.endOfStream(now()));
      return G_SOURCE_REMOVE;
    default:
      break;
  }
  return G_SOURCE_CONTINUE;
}

std::vector<std::string> Camera::unfinishedSegments() const {
  return pipeline_ ? pipeline_->writer().unfinished() : std::vector<std::string>{};
}

}  // namespace wircam::recorder
