#include "record/segment_inspector.h"

#include <gst/gst.h>

#include <atomic>
#include <chrono>

#include "record/segment_planner.h"

namespace wircam::recorder {

namespace {

// A damaged segment's demuxer may neither end nor give a frame: it is given
// up after this long without one.
constexpr GstClockTime kStallLimit = 2 * GST_SECOND;
constexpr GstClockTime kWaitSlice = 100 * GST_MSECOND;

struct VideoSpan {
  std::atomic<uint64_t> frames = 0;  // counted on the streaming thread
  GstClockTime first = GST_CLOCK_TIME_NONE, last = 0, lastDuration = 0;
};

GstPadProbeReturn countFrame(GstPad*, GstPadProbeInfo* info, gpointer data) {
  auto* span = static_cast<VideoSpan*>(data);
  GstBuffer* buffer = GST_PAD_PROBE_INFO_BUFFER(info);
  GstClockTime pts = GST_BUFFER_PTS(buffer);
  ++span->frames;
  if (GST_CLOCK_TIME_IS_VALID(pts)) {
    if (!GST_CLOCK_TIME_IS_VALID(span->first) || pts < span->first) span->first = pts;
    if (pts >= span->last) {
      span->last = pts;
      span->lastDuration = GST_BUFFER_DURATION_IS_VALID(buffer) ? GST_BUFFER_DURATION(buffer) : 0;
    }
  }
  return GST_PAD_PROBE_OK;
}

// Each demuxed stream goes to a fakesink; the video's buffers are counted.
void onPadAdded(GstElement* demuxer, GstPad* pad, gpointer data) {
  GstElement* pipeline = GST_ELEMENT(gst_element_get_parent(demuxer));
  GstElement* sink = gst_element_factory_make("fakesink", nullptr);
  g_object_set(sink, "sync", FALSE, nullptr);
  gst_bin_add(GST_BIN(pipeline), sink);
  gst_element_sync_state_with_parent(sink);
  GstPad* sinkPad = gst_element_get_static_pad(sink, "sink");
  gst_pad_link(pad, sinkPad);
  gst_object_unref(sinkPad);
  GstCaps* caps = gst_pad_query_caps(pad, nullptr);
  const char* media = gst_structure_get_name(gst_caps_get_structure(caps, 0));
  if (g_str_has_prefix(media, "video/") || g_str_has_prefix(media, "image/"))
    gst_pad_add_probe(pad, GST_PAD_PROBE_TYPE_BUFFER, countFrame, data, nullptr);
  gst_caps_unref(caps);
  gst_object_unref(pipeline);
}

}  // namespace

std::optional<IndexEntry> inspectSegment(const std::filesystem::path& file) {
  const char* demuxerName = file.extension() == ".mp4" ? "qtdemux" : "matroskademux";
  GstElement* pipeline = gst_pipeline_new(nullptr);
  GstElement* source = gst_element_factory_make("filesrc", nullptr);
  GstElement* demuxer = gst_element_factory_make(demuxerName, nullptr);
  if (!source || !demuxer) {
    if (source) gst_object_unref(source);
    if (demuxer) gst_object_unref(demuxer);
    gst_object_unref(pipeline);
    return std::nullopt;
  }
  g_object_set(source, "location", file.c_str(), nullptr);
  gst_bin_add_many(GST_BIN(pipeline), source, demuxer, nullptr);
  gst_element_link(source, demuxer);
  VideoSpan span;
  g_signal_connect(demuxer, "pad-added", G_CALLBACK(onPadAdded), &span);
  gst_element_set_state(pipeline, GST_STATE_PLAYING);
  GstBus* bus = gst_element_get_bus(pipeline);
  // A segment is read in milliseconds; a damaged one ends in an error or
  // stalls.
  uint64_t seen = 0;
  for (GstClockTime quiet = 0; quiet < kStallLimit;) {
    GstMessage* end = gst_bus_timed_pop_filtered(
        bus, kWaitSlice, static_cast<GstMessageType>(GST_MESSAGE_EOS | GST_MESSAGE_ERROR));
    if (end) {
      gst_message_unref(end);
      break;
    }
    uint64_t frames = span.frames;
    quiet = frames == seen ? quiet + kWaitSlice : 0;
    seen = frames;
  }
  gst_object_unref(bus);
  gst_element_set_state(pipeline, GST_STATE_NULL);
  gst_object_unref(pipeline);
  if (span.frames == 0) return std::nullopt;

  IndexEntry entry;
  entry.file = file.filename().string();
  std::error_code error;
  entry.bytes = std::filesystem::file_size(file, error);
  entry.frames = span.frames;
  GstClockTime period = span.lastDuration
                            ? span.lastDuration
                            : (span.last - span.first) / std::max<uint64_t>(span.frames - 1, 1);
  entry.durationSeconds = static_cast<double>(span.last - span.first + period) / GST_SECOND;
  if (auto name = parseSegmentName(entry.file)) {
    entry.camera = name->camera;
    entry.startUtc = name->startUtc;
  } else {
    auto written = std::chrono::file_clock::to_sys(std::filesystem::last_write_time(file, error));
    auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(written.time_since_epoch());
    entry.camera = file.stem().string();
    entry.startUtc =
        SegmentPlanner::isoUtc(ms.count() - static_cast<int64_t>(entry.durationSeconds * 1000));
  }
  return entry;
}

}  // namespace wircam::recorder
