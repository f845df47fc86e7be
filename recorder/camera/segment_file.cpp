#include "camera/segment_file.h"

#include <cerrno>
#include <cstring>
#include <utility>

#include "camera/disk_sink.h"
#include "telemetry/collect_pads_turns.h"

namespace wircam::recorder {

Expected<GstElement*, std::string> SegmentFile::makeSink(const CameraDisk& disk) {
  if (disk.writer) {
    auto file = DiskWriter::open(path_);
    if (!file) {
      // On the bus, as filesink's would be: the camera starts again (or,
      // the disk full, stops).
      int why = file.error();
      int code = why == ENOSPC || why == EDQUOT ? GST_RESOURCE_ERROR_NO_SPACE_LEFT
                                                : GST_RESOURCE_ERROR_OPEN_WRITE;
      std::string message = "cannot open " + path_ + ": " + std::strerror(why);
      GError* error = g_error_new_literal(GST_RESOURCE_ERROR, code, message.c_str());
      gst_element_post_message(pipeline_,
                               gst_message_new_error(GST_OBJECT(pipeline_), error, nullptr));
      g_error_free(error);
      return unexpected(message);
    }
    // (Without `this`: a file cut off on a slow disk may be written after
    // the camera has let go of it.)
    return makeDiskSink(disk.writer, std::move(*file), disk.budget,
                        [path = path_](GstElement* sink) { postClosed(sink, path); });
  }
  GstElement* sink = gst_element_factory_make("filesink", nullptr);
  if (!sink) return unexpected(std::string("no filesink (gst-plugins-good)"));
  writtenBySink_ = true;
  // filesink would gather 64 KB before it writes: minutes of a low-rate
  // stream that a crash would lose; the muxers write in pieces of a frame
  // or more. Not async: a sink added to a playing pipeline must not take
  // it back to PAUSED until its first frame.
  g_object_set(sink, "location", path_.c_str(), "async", FALSE, nullptr);
  gst_util_set_object_arg(G_OBJECT(sink), "buffer-mode", "unbuffered");
  return sink;
}

Expected<std::unique_ptr<SegmentFile>, std::string> SegmentFile::open(
    GstElement* pipeline, const MuxerSpec& muxer, const CameraDisk& disk, const std::string& path,
    GstClockTime start, uint64_t number) {
  std::unique_ptr<SegmentFile> file(new SegmentFile);
  file->pipeline_ = pipeline;
  file->path_ = path;
  file->start_ = start;
  file->number_ = number;
  file->muxer_ = gst_element_factory_make(muxer.factory.c_str(), nullptr);
  if (!file->muxer_) return unexpected("no " + muxer.factory + " (gst-plugins-good)");
  auto sink = file->makeSink(disk);
  if (!sink) {
    gst_object_unref(std::exchange(file->muxer_, nullptr));
    return unexpected(sink.error());
  }
  file->sink_ = *sink;
  for (const auto& [name, value] : muxer.properties)
    gst_util_set_object_arg(G_OBJECT(file->muxer_), name.c_str(), value.c_str());
  gst_bin_add_many(GST_BIN(pipeline), file->muxer_, file->sink_, nullptr);
  gst_element_link(file->muxer_, file->sink_);
  GstPad* sinkPad = gst_element_get_static_pad(file->sink_, "sink");
  gst_pad_add_probe(sinkPad, GST_PAD_PROBE_TYPE_EVENT_DOWNSTREAM, onSinkEvent, file.get(), nullptr);
  gst_object_unref(sinkPad);
  file->videoInput_ = gst_element_request_pad_simple(file->muxer_, "video_%u");
  if (muxer.text) file->textInput_ = gst_element_request_pad_simple(file->muxer_, "subtitle_%u");
  for (GstPad* input : {file->videoInput_, file->textInput_})
    if (input) gst_pad_set_offset(input, -static_cast<gint64>(start));
  // (Each failure is also an error on the bus, which restarts the camera.)
  if (!file->videoInput_ || (muxer.text && !file->textInput_))
    return unexpected(muxer.factory + " takes no video or text input");
  file->takesTurns_ = file->textInput_ && collect_pads_turns::drive(file->videoInput_);
  if (!gst_element_sync_state_with_parent(file->sink_) ||
      !gst_element_sync_state_with_parent(file->muxer_))
    return unexpected("cannot open " + path);
  gst_element_post_message(
      file->sink_,
      gst_message_new_element(
          GST_OBJECT(file->sink_),
          gst_structure_new(kOpenedMessage, "location", G_TYPE_STRING, path.c_str(), nullptr)));
  return file;
}

SegmentFile::~SegmentFile() {
  if (!muxer_) return;
  for (GstElement* element : {sink_, muxer_}) gst_element_set_state(element, GST_STATE_NULL);
  for (GstPad* input : {videoInput_, textInput_}) {
    if (!input) continue;
    gst_element_release_request_pad(muxer_, input);
    gst_object_unref(input);
  }
  for (GstElement* element : {sink_, muxer_}) gst_bin_remove(GST_BIN(pipeline_), element);
}

bool SegmentFile::letLineIn(GstClockTime position) {
  if (!takesTurns_) return true;
  if (!collect_pads_turns::openForLine(videoInput_, position)) return false;
  linesOpen_ = true;
  return true;
}

void SegmentFile::afterLines() {
  if (std::exchange(linesOpen_, false)) collect_pads_turns::afterLines(videoInput_, textInput_);
}

void SegmentFile::end(GstPad* input, std::atomic<bool>& ended) {
  if (input && !ended.exchange(true)) gst_pad_send_event(input, gst_event_new_eos());
}

GstPadProbeReturn SegmentFile::onSinkEvent(GstPad*, GstPadProbeInfo* info, gpointer data) {
  auto* self = static_cast<SegmentFile*>(data);
  if (GST_EVENT_TYPE(GST_PAD_PROBE_INFO_EVENT(info)) != GST_EVENT_EOS) return GST_PAD_PROBE_OK;
  self->closed_ = true;
  if (self->writtenBySink_) postClosed(self->sink_, self->path_);
  return GST_PAD_PROBE_OK;
}

void SegmentFile::postClosed(GstElement* sink, const std::string& path) {
  gst_element_post_message(
      sink, gst_message_new_element(GST_OBJECT(sink),
                                    gst_structure_new(kClosedMessage, "location", G_TYPE_STRING,
                                                      path.c_str(), nullptr)));
}

void SegmentFile::endVideoAtTheRunsEnd() {
  diskSinkWaitsAtEnd(sink_);
  endVideo();
}

}  // namespace wircam::recorder
