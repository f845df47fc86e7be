#include "export/muxed_export.h"

#include <gst/app/gstappsrc.h>

#include <utility>

#include "telemetry/telemetry_track.h"
#include "telemetry/telemetry_track_flags.h"

namespace wircam::recorder {

MuxedExport::MuxedExport(std::string path, std::string container)
    : path_(std::move(path)), container_(std::move(container)) {}

MuxedExport::~MuxedExport() {
  if (pending_) gst_buffer_unref(pending_);
  if (!pipeline_) return;
  gst_element_set_state(pipeline_, GST_STATE_NULL);
  gst_object_unref(video_);
  gst_object_unref(text_);
  gst_object_unref(pipeline_);
}

std::optional<std::string> MuxedExport::start(GstCaps* caps) {
  bool mkv = container_ == "mkv";
  if (!mkv && gst_structure_has_name(gst_caps_get_structure(caps, 0), "image/jpeg"))
    return "mp4 needs H.264 recordings: GStreamer's mp4mux cannot carry the camera's "
           "JPEG frames as they are (use mkv or mcap to keep them untouched)";
  // The text track is named as in the recordings (in Matroska a
  // placeholder, rewritten when the file is done: telemetry_track_flags.h).
  gchar* location = g_strescape(path_.c_str(), nullptr);
  std::string description =
      std::string("appsrc name=video format=time block=true max-bytes=8000000 ! mux.video_%u ") +
      (mkv ? "matroskamux" : "mp4mux") + " name=mux ! filesink location=\"" + location +
      "\" appsrc name=text format=time caps=\"text/x-raw,format=(string)utf8\" ! taginject "
      "name=title "
      "tags=\"title=" +
      std::string(mkv ? kTelemetryTrackPlaceholder : kTelemetryTrackName) + "\" ! mux.subtitle_%u";
  g_free(location);
  GError* error = nullptr;
  pipeline_ = gst_parse_launch(description.c_str(), &error);
  if (error) {
    std::string message = error->message;
    g_error_free(error);
    pipeline_ = nullptr;
    return "cannot build the " + container_ + " muxer: " + message;
  }
  video_ = gst_bin_get_by_name(GST_BIN(pipeline_), "video");
  text_ = gst_bin_get_by_name(GST_BIN(pipeline_), "text");
  gst_app_src_set_caps(GST_APP_SRC(video_), caps);
  // Gaps become what the muxer wants after taginject, which sends the
  // track's title with the first buffer it sees: a GAP event would pass it
  // by, and the title could miss the file's header.
  GstElement* title = gst_bin_get_by_name(GST_BIN(pipeline_), "title");
  GstPad* textOut = gst_element_get_static_pad(title, "src");
  gst_object_unref(title);
  gst_pad_add_probe(textOut, GST_PAD_PROBE_TYPE_BUFFER, onText, this, nullptr);
  gst_object_unref(textOut);
  if (gst_element_set_state(pipeline_, GST_STATE_PLAYING) == GST_STATE_CHANGE_FAILURE)
    return failure().value_or("cannot write " + path_);
  return std::nullopt;
}

GstPadProbeReturn MuxedExport::onText(GstPad* pad, GstPadProbeInfo* info, gpointer self) {
  if (!TelemetryTrack::isGap(GST_PAD_PROBE_INFO_BUFFER(info))) return GST_PAD_PROBE_OK;
  return TelemetryTrack::passGap(pad, info, static_cast<MuxedExport*>(self)->container_ == "mkv");
}

std::optional<std::string> MuxedExport::frame(GstBuffer* buffer, int64_t ptsNs, int64_t, bool) {
  // A muxer hands on a frame once the text has passed its time: when no
  // line did, a gap says there is none until then.
  if (textPts_ < ptsNs) {
    GstBuffer* gap = gst_buffer_new();
    GST_BUFFER_PTS(gap) = static_cast<GstClockTime>(ptsNs);
    GST_BUFFER_DURATION(gap) = GST_MSECOND;
    GST_BUFFER_FLAG_SET(gap, GST_BUFFER_FLAG_GAP);
    gst_app_src_push_buffer(GST_APP_SRC(text_), gap);
    textPts_ = ptsNs;
  }
  if (pending_)
    if (auto problem = pushPending(ptsNs - pendingPts_)) return problem;
  // Its bytes shared, not copied; its times its own on the new timeline.
  pending_ = gst_buffer_copy(buffer);
  pendingPts_ = ptsNs;
  GST_BUFFER_PTS(pending_) = GST_BUFFER_DTS(pending_) = static_cast<GstClockTime>(ptsNs);
  return std::nullopt;
}

std::optional<std::string> MuxedExport::pushPending(int64_t durationNs) {
  lastDuration_ = durationNs;
  GST_BUFFER_DURATION(pending_) = static_cast<GstClockTime>(durationNs);
  GstBuffer* out = std::exchange(pending_, nullptr);
  if (gst_app_src_push_buffer(GST_APP_SRC(video_), out) != GST_FLOW_OK)
    return failure().value_or("the muxer stopped taking frames");
  return std::nullopt;
}

std::optional<std::string> MuxedExport::line(const nlohmann::json& line, int64_t ptsNs, int64_t) {
  std::string text = line.dump();
  GstBuffer* buffer = gst_buffer_new_memdup(text.data(), text.size());
  textPts_ = std::max(textPts_, ptsNs);  // a track's times rise
  GST_BUFFER_PTS(buffer) = static_cast<GstClockTime>(textPts_);
  GST_BUFFER_DURATION(buffer) = GST_MSECOND;
  gst_app_src_push_buffer(GST_APP_SRC(text_), buffer);
  return failure();
}

std::optional<std::string> MuxedExport::finish() {
  if (pending_)
    if (auto problem = pushPending(lastDuration_)) return problem;
  gst_app_src_end_of_stream(GST_APP_SRC(video_));
  gst_app_src_end_of_stream(GST_APP_SRC(text_));
  GstBus* bus = gst_element_get_bus(pipeline_);
  GstMessage* message = gst_bus_timed_pop_filtered(
      bus, GST_CLOCK_TIME_NONE, static_cast<GstMessageType>(GST_MESSAGE_EOS | GST_MESSAGE_ERROR));
  gst_object_unref(bus);
  std::optional<std::string> problem;
  if (GST_MESSAGE_TYPE(message) == GST_MESSAGE_ERROR) {
    GError* error = nullptr;
    gst_message_parse_error(message, &error, nullptr);
    problem = "cannot write " + path_ + ": " + error->message;
    g_error_free(error);
  }
  gst_message_unref(message);
  gst_element_set_state(pipeline_, GST_STATE_NULL);
  if (!problem) markTelemetryTrack(path_);
  return problem;
}

std::optional<std::string> MuxedExport::failure() {
  GstBus* bus = gst_element_get_bus(pipeline_);
  GstMessage* message = gst_bus_pop_filtered(bus, GST_MESSAGE_ERROR);
  gst_object_unref(bus);
  if (!message) return std::nullopt;
  GError* error = nullptr;
  gst_message_parse_error(message, &error, nullptr);
  std::string text = "cannot write " + path_ + ": " + error->message;
  g_error_free(error);
  gst_message_unref(message);
  return text;
}

}  // namespace wircam::recorder
