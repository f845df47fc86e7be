#include "recording/segment_reader.h"

#include <gst/app/gstappsink.h>

#include <fstream>
#include <optional>
#include <utility>

#include "gst_h264_start.h"

namespace wircam::recorder {

SegmentFrame::SegmentFrame(SegmentFrame&& other) noexcept
    : buffer(std::exchange(other.buffer, nullptr)), ptsNs(other.ptsNs), key(other.key) {}

SegmentFrame& SegmentFrame::operator=(SegmentFrame&& other) noexcept {
  std::swap(buffer, other.buffer);
  ptsNs = other.ptsNs;
  key = other.key;
  return *this;
}

SegmentFrame::~SegmentFrame() {
  if (buffer) gst_buffer_unref(buffer);
}

Expected<std::unique_ptr<SegmentReader>, std::string> SegmentReader::open(
    const std::filesystem::path& video) {
  std::unique_ptr<SegmentReader> reader(new SegmentReader);
  bool mp4 = video.extension() == ".mp4";
  // The video track only (caps pick it); the text track stays unlinked.
  gchar* location = g_strescape(video.c_str(), nullptr);
  std::string description = std::string("filesrc location=\"") + location + "\" ! " +
                            (mp4 ? "qtdemux" : "matroskademux") +
                            " ! appsink name=frames sync=false max-buffers=8 "
                            "caps=\"image/jpeg;video/x-h264\"";
  g_free(location);
  GError* error = nullptr;
  reader->pipeline_ = gst_parse_launch(description.c_str(), &error);
  if (error) {
    std::string message = error->message;
    g_error_free(error);
    return unexpected("cannot read " + video.string() + ": " + message);
  }
  reader->sink_ = gst_bin_get_by_name(GST_BIN(reader->pipeline_), "frames");
  if (gst_element_set_state(reader->pipeline_, GST_STATE_PLAYING) == GST_STATE_CHANGE_FAILURE)
    return unexpected("cannot read " + video.string());
  return reader;
}

SegmentReader::~SegmentReader() {
  if (pipeline_) gst_element_set_state(pipeline_, GST_STATE_NULL);
  if (sink_) gst_object_unref(sink_);
  if (pipeline_) gst_object_unref(pipeline_);
  if (caps_) gst_caps_unref(caps_);
}

namespace {

constexpr GstClockTime kWaitSlice = 50 * GST_MSECOND;
// Longer than any healthy segment takes to give its next frame (its
// demuxer reads from a local file), short enough that a broken one is
// given up before a user wonders.
constexpr GstClockTime kStallLimit = 2 * GST_SECOND;

// The demuxer's error, if it posted one: what is wrong with the file.
std::optional<std::string> demuxerError(GstElement* pipeline) {
  GstBus* bus = gst_element_get_bus(pipeline);
  GstMessage* message = gst_bus_pop_filtered(bus, GST_MESSAGE_ERROR);
  gst_object_unref(bus);
  if (!message) return std::nullopt;
  GError* error = nullptr;
  gst_message_parse_error(message, &error, nullptr);
  std::string text = error ? error->message : "unreadable";
  if (error) g_error_free(error);
  gst_message_unref(message);
  return text;
}

}  // namespace

bool isWholeJpeg(GstBuffer* jpeg) {
  gsize size = gst_buffer_get_size(jpeg);
  guint8 end[2] = {0, 0};
  return size >= 4 && gst_buffer_extract(jpeg, size - 2, end, 2) == 2 && end[0] == 0xFF &&
         end[1] == 0xD9;
}

Expected<std::optional<SegmentFrame>, std::string> SegmentReader::next() {
  // A demuxer that errors (zeros, random bytes, text named .mkv) or finds
  // no video track never ends the appsink's stream: a plain pull would wait
  // for ever. So the wait is in slices, each ended by a frame, the stream's
  // end or the demuxer's error, and a file that gives none of them for
  // kStallLimit is given up.
  GstSample* sample = nullptr;
  for (GstClockTime waited = 0; !sample; waited += kWaitSlice) {
    sample = gst_app_sink_try_pull_sample(GST_APP_SINK(sink_), kWaitSlice);
    if (sample) break;
    if (auto error = demuxerError(pipeline_)) return unexpected(*error);
    if (gst_app_sink_is_eos(GST_APP_SINK(sink_))) return std::optional<SegmentFrame>();
    if (waited >= kStallLimit)
      return unexpected(std::string(caps_ ? "no further frame" : "no video frame") + " within " +
                        std::to_string(kStallLimit / GST_SECOND) + " s");
  }
  if (!caps_) caps_ = gst_caps_ref(gst_sample_get_caps(sample));
  SegmentFrame frame;
  frame.buffer = gst_buffer_ref(gst_sample_get_buffer(sample));
  GstSegment* segment = gst_sample_get_segment(sample);
  GstClockTime pts = GST_BUFFER_PTS(frame.buffer);
  GstClockTime time =
      segment ? gst_segment_to_stream_time(segment, GST_FORMAT_TIME, pts) : GST_CLOCK_TIME_NONE;
  frame.ptsNs = GST_CLOCK_TIME_IS_VALID(time) ? static_cast<int64_t>(time) : 0;
  // Whether a decoder can start here, from the bitstream: matroskademux
  // flags no H.264 frame as a delta (gst_h264_start.h). Every JPEG is one.
  bool h264 = gst_structure_has_name(gst_caps_get_structure(caps_, 0), "video/x-h264");
  frame.key = !h264 || gst::h264StartsDecoding(frame.buffer, caps_);
  gst_sample_unref(sample);
  if (gst_structure_has_name(gst_caps_get_structure(caps_, 0), "image/jpeg") &&
      !isWholeJpeg(frame.buffer))
    return unexpected(std::string("a JPEG frame without its end marker (the file is damaged)"));
  return std::optional<SegmentFrame>(std::move(frame));
}

std::vector<std::string> sidecarLines(const std::filesystem::path& video) {
  std::ifstream in(std::filesystem::path(video).replace_extension(".jsonl"));
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) lines.push_back(std::move(line));
  return lines;
}

}  // namespace wircam::recorder
