#include "camera/camera.h"

#include "log_line.h"
#include "wirc_bus_messages.h"

namespace wircam::recorder {

namespace {
CameraHealth::Clock::time_point now() { return CameraHealth::Clock::now(); }
int64_t unixMsNow() { return g_get_real_time() / 1000; }
}  // namespace

Camera::Camera(StreamPlan plan, CameraFiles files, CameraHealth::Policy policy,
               CameraObserver& observer)
    : plan_(std::move(plan)),
      files_(std::move(files)),
      observer_(observer),
      health_(policy, now()) {
  report_.name = plan_.name;
  report_.device = plan_.device;
  report_.camera = plan_.camera;
  report_.state = toString(state_);
  report_.stateSinceUnixMs = unixMsNow();
  report_.positions = !plan_.positions.empty();
}

Expected<std::unique_ptr<Camera>, std::string> Camera::create(StreamPlan plan, CameraFiles files,
                                                              CameraHealth::Policy policy,
                                                              CameraObserver& observer) {
  std::unique_ptr<Camera> camera(new Camera(std::move(plan), std::move(files), policy, observer));
  auto pipeline = CameraPipeline::build(camera->plan_, camera->files_, camera->frames(),
                                        camera->encodedFrames());
  if (!pipeline) return unexpected(pipeline.error());
  camera->pipeline_ = std::move(*pipeline);
  return camera;
}

Camera::~Camera() {
  for (guint timer : {finishDeadline_, restartTimer_})
    if (timer) g_source_remove(timer);
  if (busWatch_) g_source_remove(busWatch_);
  pipeline_.reset();
}

void Camera::watchBus() {
  GstBus* bus = gst_element_get_bus(pipeline_->pipeline());
  busWatch_ = gst_bus_add_watch(bus, onBusMessage, this);
  gst_object_unref(bus);
}

bool Camera::play() {
  watchBus();
  if (gst_element_set_state(pipeline_->pipeline(), GST_STATE_PLAYING) != GST_STATE_CHANGE_FAILURE)
    return true;
  // The error itself is on the bus: say it.
  GstBus* bus = gst_element_get_bus(pipeline_->pipeline());
  if (GstMessage* message = gst_bus_pop_filtered(bus, GST_MESSAGE_ERROR)) {
    GError* error = nullptr;
    gst_message_parse_error(message, &error, nullptr);
    logLine(name() + ": cannot start: " + error->message);
    g_error_free(error);
    gst_message_unref(message);
  }
  gst_object_unref(bus);
  return false;
}

bool Camera::start() { return play(); }

GstElement* Camera::controller() const {
  return pipeline_ ? pipeline_->element(plan_.controller) : nullptr;
}

void Camera::tick() {
  if (pipeline_ && !finishing_) {
    uint64_t frames = pipeline_->framesPlanned();
    if (frames != framesSeen_) health_.frame(now());
    framesSeen_ = frames;
    if (health_.stalled(now()))
      fault(CameraFault::kStall,
            "no frame for " +
                std::to_string(std::chrono::duration_cast<std::chrono::milliseconds>(
                                   health_.policy().stallTimeout)
                                   .count()) +
                " ms while logged in");
  }
  followState();
}

void Camera::followState() {
  CameraState state = health_.state(now());
  if (state == state_) return;
  state_ = state;
  report_.state = toString(state);
  report_.stateSinceUnixMs = unixMsNow();
  logLine(name() + ": " + report_.state +
          (report_.linkReason.empty() ? "" : " (" + report_.linkReason + ")"));
  observer_.event(*this, {{"type", "state"}, {"state", report_.state}});
}

void Camera::fault(CameraFault fault, const std::string& why) {
  if (stopping_ || finishing_ || !pipeline_) return;
  restartAt_ = health_.fault(fault, now());
  auto delay = std::chrono::duration_cast<std::chrono::milliseconds>(restartAt_ - now());
  logLine(name() + ": " + why + ": closing its file and starting its pipeline again in " +
          std::to_string(delay.count()) + " ms");
  followState();
  finish(Then::kRestart);
}

void Camera::finish(Then then) {
  if (!pipeline_ || finishing_) return;
  if (then == Then::kRestart) {
    auto waiting = pipeline_->telemetry().handOver();
    carriedTelemetry_.insert(carriedTelemetry_.end(), std::make_move_iterator(waiting.begin()),
                             std::make_move_iterator(waiting.end()));
  } else {
    // What waited for frames that will not come goes into the last file.
    pipeline_->telemetry().finish();
  }
  if (!pipeline_->hasFrames()) {
    tearDown();  // no file to finish (and no EOS would pass a camera that never sent a frame)
    return;
  }
  finishing_ = true;
  pipeline_->writer().end();
  finishDeadline_ = g_timeout_add(static_cast<guint>(kFinishTime.count()), onFinishDeadline, this);
}

gboolean Camera::onFinishDeadline(gpointer data) {
  auto* self = static_cast<Camera*>(data);
  self->finishDeadline_ = 0;
  logLine(self->name() + ": cut off after " + std::to_string(kFinishTime.count()) +
          " ms (its last file is indexed as it is)");
  self->tearDown();
  return G_SOURCE_REMOVE;
}

void Camera::tearDown() {
  if (finishDeadline_) g_source_remove(std::exchange(finishDeadline_, 0));
  if (busWatch_) g_source_remove(std::exchange(busWatch_, 0));
  if (GstElement* control = controller()) {
    // What the user set (following, the target) carries over to the next run.
    gboolean enabled = FALSE;
    gint target = -1;
    g_object_get(control, "enabled", &enabled, "target-id", &target, nullptr);
    carriedControl_ = {enabled != FALSE, target};
  }
  if (pipeline_) {
    gst_element_set_state(pipeline_->pipeline(), GST_STATE_NULL);
    // A file EOS did not finish is still playable (Matroska written in
    // clusters, fragmented MP4): indexed like any other.
    for (const auto& file : pipeline_->writer().unfinished()) closed(file);
  }
  report_.segment.clear();
  pipeline_.reset();
  finishing_ = false;
  framesSeen_ = 0;
  statsTime_ = GST_CLOCK_TIME_NONE;
  earlierRuns_.frames += runCounts_.frames;
  earlierRuns_.incomplete += runCounts_.incomplete;
  earlierRuns_.bytes += runCounts_.bytes;
  earlierRuns_.commandsSent += runCounts_.commandsSent;
  runCounts_ = {};
  if (stopping_) {
    ended_ = true;
    observer_.ended(*this);
    return;
  }
  // A pipeline that ended by itself (no fault said so) failed too.
  if (!health_.restartPending()) restartAt_ = health_.fault(CameraFault::kError, now());
  auto delay = std::chrono::duration_cast<std::chrono::milliseconds>(restartAt_ - now());
  restartTimer_ =
      g_timeout_add(static_cast<guint>(std::max<int64_t>(0, delay.count())), onRestart, this);
}

gboolean Camera::onRestart(gpointer data) {
  auto* self = static_cast<Camera*>(data);
  self->restartTimer_ = 0;
  auto pipeline =
      CameraPipeline::build(self->plan_, self->files_, self->frames(), self->encodedFrames());
  if (!pipeline) {
    logLine(self->name() + ": " + pipeline.error());
    return G_SOURCE_REMOVE;
  }
  self->pipeline_ = std::move(*pipeline);
  if (GstElement* control = self->controller(); control && self->carriedControl_)
    g_object_set(control, "enabled", self->carriedControl_->first ? TRUE : FALSE, "target-id",
                 self->carriedControl_->second, nullptr);
  // What the last run left waiting opens this run's first file.
  for (auto& line : std::exchange(self->carriedTelemetry_, {}))
    self->pipeline_->telemetry().write(std::move(line.json), 0, line.unixMs);
  self->health_.restarted(now());
  self->report_.restarts = self->health_.restarts();
  logLine(self->name() + ": pipeline started again (restart " +
          std::to_string(self->health_.restarts()) + ")");
  if (!self->play()) self->fault(CameraFault::kError, "its pipeline did not start");
  self->followState();
  return G_SOURCE_REMOVE;
}

void Camera::closed(const std::string& file) {
  auto planned = pipeline_ ? pipeline_->planner().segmentOf(file) : std::nullopt;
  ++filesClosed_;
  if (planned)
    observer_.segmentClosed(*this, file, *planned);
  else
    logLine(name() + ": " + file + " was not planned; not indexed");
}

void Camera::stop() {
  if (stopping_) return;
  stopping_ = true;
  if (restartTimer_) g_source_remove(std::exchange(restartTimer_, 0));
  if (!pipeline_) {
    ended_ = true;
    observer_.ended(*this);
    return;
  }
  if (finishing_) return;  // a fault's finish is under way: its end is the end
  finish(Then::kEnd);
}

void Camera::halt() {
  if (ended_) return;
  stopping_ = true;
  if (restartTimer_) g_source_remove(std::exchange(restartTimer_, 0));
  if (pipeline_)
    tearDown();
  else
    ended_ = true;
}

void Camera::handleError(GstMessage* message) {
  GError* error = nullptr;
  gchar* debug = nullptr;
  gst_message_parse_error(message, &error, &debug);
  bool diskFull = g_error_matches(error, GST_RESOURCE_ERROR, GST_RESOURCE_ERROR_NO_SPACE_LEFT);
  std::string what = error->message;
  logLine(std::string(GST_OBJECT_NAME(GST_MESSAGE_SRC(message))) + ": " + what + "\n" +
          (debug ? debug : ""));
  g_error_free(error);
  g_free(debug);
  if (diskFull) {
    // This camera's file cannot be finished; the others may still be.
    stopping_ = true;
    observer_.diskFull(*this);
    tearDown();
    return;
  }
  if (finishing_ || stopping_) {
    tearDown();  // an error while finishing: what the file holds is what it holds
    return;
  }
  // An error ends this run of the pipeline at once: EOS would not pass.
  restartAt_ = health_.fault(CameraFault::kError, now());
  logLine(name() + ": restarting its pipeline after the error above; the other cameras record on");
  followState();
  tearDown();
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
      self->tearDown();
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
