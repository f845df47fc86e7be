#include "camera/camera_pipeline.h"

namespace wircam::recorder {

Expected<std::unique_ptr<CameraPipeline>, std::string> CameraPipeline::build(
    const StreamPlan& plan, const CameraFiles& files, FrameTap* frames, FrameTap* encoded) {
  std::unique_ptr<CameraPipeline> camera(new CameraPipeline);
  GError* parseError = nullptr;
  camera->pipeline_ = gst_parse_launch(plan.description.c_str(), &parseError);
  if (parseError) {
    std::string message = parseError->message;
    g_error_free(parseError);
    return unexpected("cannot build the pipeline (are the wircam plugins on GST_PLUGIN_PATH?): " +
                      message);
  }
  // A description of one element (wircsrc alone, without a text track or
  // branches) parses to that element, not to a pipeline.
  if (!GST_IS_PIPELINE(camera->pipeline_)) {
    GstElement* alone = camera->pipeline_;
    camera->pipeline_ = gst_pipeline_new(nullptr);
    gst_bin_add(GST_BIN(camera->pipeline_), alone);
  }
  // Named after its camera, so that the log says whose it is.
  gst_object_set_name(GST_OBJECT(camera->pipeline_), plan.name.c_str());
  camera->planner_ =
      std::make_unique<SegmentPlanner>(files.folder, plan.name, files.extension, files.limits);
  camera->track_ =
      std::make_unique<TelemetryTrack>(camera->textOutlet(plan), !plan.muxer.textGapEvents);
  camera->telemetry_ = std::make_unique<TelemetryRouter>(*camera->planner_, *camera->track_);
  if (plan.recordBound > 0) {
    auto writer = DiskWriter::of(files.folder);
    if (!writer) return unexpected(writer.error());
    camera->disk_ = {std::move(*writer), std::make_shared<DiskBudget>(plan.recordBound)};
  }
  camera->writer_ = std::make_unique<SegmentWriter>(
      SegmentWriter::Parts{.pipeline = camera->pipeline_,
                           .source = camera->element(plan.source),
                           .planPoint = camera->element(plan.planPoint),
                           .videoTail = camera->element(plan.videoTail),
                           .textTail = camera->element(plan.telemetryTail),
                           .muxer = plan.muxer,
                           .disk = camera->disk_,
                           .transcoded = files.transcoded},
      *camera->planner_, *camera->track_, [self = camera.get()] {
        self->telemetry_->onFrame();
        self->framesPlanned_.fetch_add(1, std::memory_order_relaxed);
      });
  if (frames && !plan.liveSink.empty()) {
    frames->attach(camera->element(plan.liveSink));
    camera->frames_ = frames;
  }
  if (encoded && files.transcoded) {
    GstPad* pad = gst_element_get_static_pad(camera->element(plan.videoTail), "src");
    encoded->attachPad(pad);
    gst_object_unref(pad);
    camera->encoded_ = encoded;
  }
  return camera;
}

CameraPipeline::~CameraPipeline() {
  if (!pipeline_) return;
  gst_element_set_state(pipeline_, GST_STATE_NULL);
  if (frames_) frames_->detach();
  if (encoded_) encoded_->detach();
  // The writer holds the elements' pads: before the pipeline goes.
  writer_.reset();
  telemetry_.reset();
  track_.reset();
  gst_object_unref(pipeline_);
}

std::unique_ptr<TextOutlet> CameraPipeline::textOutlet(const StreamPlan& plan) const {
  if (GstElement* appsrc = element(plan.telemetrySource)) return appSrcOutlet(appsrc);
  GstElement* tail = element(plan.telemetryTail);
  if (!tail) return nullptr;
  GstPad* input = gst_element_get_static_pad(tail, "sink");
  auto outlet = frameThreadOutlet(input);
  gst_object_unref(input);
  return outlet;
}

GstElement* CameraPipeline::element(const std::string& name) const {
  if (name.empty()) return nullptr;
  GstElement* found = gst_bin_get_by_name(GST_BIN(pipeline_), name.c_str());
  if (found) gst_object_unref(found);  // the pipeline keeps it
  return found;
}

GstClockTime CameraPipeline::runningTime() const {
  GstClockTime now = GST_CLOCK_TIME_NONE;
  if (GstClock* clock = gst_element_get_clock(pipeline_)) {
    now = gst_clock_get_time(clock) - gst_element_get_base_time(pipeline_);
    gst_object_unref(clock);
  }
  return now;
}

}  // namespace wircam::recorder
