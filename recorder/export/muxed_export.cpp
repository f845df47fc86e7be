#include "export/muxed_export.h"

#include <gst/app/gstappsink.h>
#include <gst/app/gstappsrc.h>

#include <chrono>
#include <thread>
#include <utility>

#include "telemetry/telemetry_track.h"
#include "telemetry/telemetry_track_flags.h"

namespace wircam::recorder {

namespace {

// How far the muxer may fall behind the export (a slow reader of a stream):
// the bound of the export's memory.
constexpr guint64 kQueuedBytes = 8000000;

}  // namespace

MuxedExport::MuxedExport(ExportTarget target, std::string container)
    : target_(std::move(target)), container_(std::move(container)) {
  if (target_.stream >= 0) stream_ = std::make_unique<ByteStream>(target_.stream);
}

MuxedExport::~MuxedExport() {
  if (pending_) gst_buffer_unref(pending_);
  if (!pipeline_) return;
  gst_element_set_state(pipeline_, GST_STATE_NULL);
  gst_object_unref(video_);
  gst_object_unref(text_);
  gst_object_unref(out_);
  gst_object_unref(pipeline_);
}

std::optional<std::string> MuxedExport::start(GstCaps* caps) {
  bool matroska = mkv();
  if (!matroska && gst_structure_has_name(gst_caps_get_structure(caps, 0), "image/jpeg"))
    return "mp4 needs H.264 recordings: GStreamer's mp4mux cannot carry the camera's "
           "JPEG frames as they are (use mkv or mcap to keep them untouched)";
  // The text track is named as in the recordings (in Matroska a
  // placeholder, rewritten when the file is done: telemetry_track_flags.h).
  // MP4 in fragments of a second, as the recordings are: its moov (which
  // holds the text track's flags, marked in the first bytes) comes first,
  // and a file cut short keeps what it has. Streamed, nothing goes back
  // over what left: Matroska without its index (which players do without).
  std::string muxer = matroska ? (stream_ ? "matroskamux streamable=true" : "matroskamux")
                               : (stream_ ? "mp4mux fragment-duration=1000 streamable=true"
                                          : "mp4mux fragment-duration=1000");
  std::string sink = "appsink name=out sync=false emit-signals=true";
  if (!stream_) {
    gchar* location = g_strescape(target_.path.c_str(), nullptr);
    sink = std::string("filesink name=out location=\"") + location + "\"";
    g_free(location);
  }
  std::string description =
      "appsrc name=video format=time ! mux.video_%u " + muxer + " name=mux ! " + sink +
      " appsrc name=text format=time caps=\"text/x-raw,format=(string)utf8\" ! taginject "
      "name=title tags=\"title=" +
      std::string(matroska ? kTelemetryTrackPlaceholder : kTelemetryTrackName) +
      "\" ! mux.subtitle_%u";
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
  out_ = gst_bin_get_by_name(GST_BIN(pipeline_), "out");
  if (stream_) g_signal_connect(out_, "new-sample", G_CALLBACK(onBytes), this);
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
    return failure().value_or("cannot write " + target_.path);
  return std::nullopt;
}

GstFlowReturn MuxedExport::onBytes(GstElement* appsink, gpointer data) {
  auto* self = static_cast<MuxedExport*>(data);
  GstSample* sample = gst_app_sink_pull_sample(GST_APP_SINK(appsink));
  if (!sample) return GST_FLOW_FLUSHING;
  GstMapInfo map;
  bool sent = false;
  if (gst_buffer_map(gst_sample_get_buffer(sample), &map, GST_MAP_READ)) {
    std::lock_guard lock(self->streamLock_);
    sent = self->send(map.data, map.size);
    gst_buffer_unmap(gst_sample_get_buffer(sample), &map);
  }
  gst_sample_unref(sample);
  return sent ? GST_FLOW_OK : GST_FLOW_ERROR;
}

bool MuxedExport::send(const uint8_t* data, size_t size) {
  if (headerSent_) return stream_->write(data, size);
  header_.insert(header_.end(), data, data + size);
  return header_.size() < kTelemetryTrackHeaderBytes || sendHeader();
}

bool MuxedExport::sendHeader() {
  headerSent_ = true;
  markTelemetryTrackInHeader(header_, mkv() ? TrackContainer::kMatroska : TrackContainer::kMp4);
  bool sent = stream_->write(header_.data(), header_.size());
  header_ = {};
  return sent;
}

std::optional<std::string> MuxedExport::waitForRoom() {
  while (gst_app_src_get_current_level_bytes(GST_APP_SRC(video_)) >= kQueuedBytes) {
    if (auto problem = failure()) return problem;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return std::nullopt;
}

uint64_t MuxedExport::bytesWritten() {
  if (stream_) {
    std::lock_guard lock(streamLock_);
    return stream_->written();
  }
  gint64 position = 0;
  if (out_ && gst_element_query_position(out_, GST_FORMAT_BYTES, &position))
    return static_cast<uint64_t>(position);
  return 0;
}

GstPadProbeReturn MuxedExport::onText(GstPad* pad, GstPadProbeInfo* info, gpointer self) {
  if (!TelemetryTrack::isGap(GST_PAD_PROBE_INFO_BUFFER(info))) return GST_PAD_PROBE_OK;
  return TelemetryTrack::passGap(pad, info, static_cast<MuxedExport*>(self)->mkv());
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
  if (auto problem = waitForRoom()) {
    gst_buffer_unref(out);
    return problem;
  }
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
  // Until the file is written, or the stream's reader is gone (the muxer
  // may then stop without a word).
  GstBus* bus = gst_element_get_bus(pipeline_);
  std::optional<std::string> problem;
  while (true) {
    GstMessage* message = gst_bus_timed_pop_filtered(
        bus, 100 * GST_MSECOND, static_cast<GstMessageType>(GST_MESSAGE_EOS | GST_MESSAGE_ERROR));
    if (!message) {
      std::lock_guard lock(streamLock_);
      if (stream_ && !stream_->error().empty()) problem = stream_->error();
      if (problem) break;
      continue;
    }
    if (GST_MESSAGE_TYPE(message) == GST_MESSAGE_ERROR) {
      GError* error = nullptr;
      gst_message_parse_error(message, &error, nullptr);
      std::lock_guard lock(streamLock_);
      problem = stream_ && !stream_->error().empty()
                    ? stream_->error()
                    : "cannot write " + target_.path + ": " + error->message;
      g_error_free(error);
    }
    gst_message_unref(message);
    break;
  }
  gst_object_unref(bus);
  gst_element_set_state(pipeline_, GST_STATE_NULL);
  if (problem) return problem;
  if (!stream_) {
    // (Its name ends in .partial until the export renames it.)
    markTelemetryTrack(target_.path, mkv() ? TrackContainer::kMatroska : TrackContainer::kMp4);
    return std::nullopt;
  }
  // A stream shorter than a header's room.
  std::lock_guard lock(streamLock_);
  if (!headerSent_ && !sendHeader()) return stream_->error();
  return std::nullopt;
}

std::optional<std::string> MuxedExport::failure() {
  if (stream_) {
    std::lock_guard lock(streamLock_);
    if (!stream_->error().empty()) return stream_->error();
  }
  GstBus* bus = gst_element_get_bus(pipeline_);
  GstMessage* message = gst_bus_pop_filtered(bus, GST_MESSAGE_ERROR);
  gst_object_unref(bus);
  if (!message) return std::nullopt;
  GError* error = nullptr;
  gst_message_parse_error(message, &error, nullptr);
  std::string text = "cannot write " + target_.path + ": " + error->message;
  g_error_free(error);
  gst_message_unref(message);
  return text;
}

}  // namespace wircam::recorder
