#include "camera/segment_writer.h"

#include <gst/video/video-event.h>

#include <algorithm>

#include "camera/wall_clock.h"
#include "log_line.h"

namespace wircam::recorder {

namespace {

constexpr auto kDataProbe =
    static_cast<GstPadProbeType>(GST_PAD_PROBE_TYPE_BUFFER | GST_PAD_PROBE_TYPE_EVENT_DOWNSTREAM);
// Blocking probes are the ones a pad re-reads its peer after, so they may
// relink; they let every item through (PASS).
constexpr auto kRelinkProbe = static_cast<GstPadProbeType>(kDataProbe | GST_PAD_PROBE_TYPE_BLOCK);

// A buffer's running time on its pad's segment.
GstClockTime runningTimeOf(const GstSegment& segment, GstBuffer* buffer) {
  return gst_segment_to_running_time(&segment, GST_FORMAT_TIME, GST_BUFFER_DTS_OR_PTS(buffer));
}

bool isEvent(GstPadProbeInfo* info) {
  return (GST_PAD_PROBE_INFO_TYPE(info) & GST_PAD_PROBE_TYPE_EVENT_DOWNSTREAM) != 0;
}

// Keeps a pad's current segment, so buffers' running times can be known.
void keepSegment(GstPadProbeInfo* info, GstSegment& segment) {
  GstEvent* event = GST_PAD_PROBE_INFO_EVENT(info);
  if (GST_EVENT_TYPE(event) == GST_EVENT_SEGMENT) gst_event_copy_segment(event, &segment);
}

// `output` feeds `to` instead of whatever it fed. (Its peer, not the file
// we last linked it to: a muxer may finish its file, and the file leave
// the pipeline, before the input we fed it ends.)
void relink(GstPad* output, GstPad* to) {
  if (GstPad* peer = gst_pad_get_peer(output)) {
    gst_pad_unlink(output, peer);
    gst_object_unref(peer);
  }
  GstPadLinkReturn linked = gst_pad_link(output, to);
  if (linked != GST_PAD_LINK_OK)
    logLine(std::string("cannot link ") + GST_OBJECT_NAME(GST_OBJECT_PARENT(output)) + " to " +
            GST_OBJECT_NAME(GST_OBJECT_PARENT(to)) + ": " + gst_pad_link_get_name(linked));
}

}  // namespace

SegmentWriter::SegmentWriter(Parts parts, SegmentPlanner& planner, TelemetryTrack& track,
                             std::function<void()> afterFrame)
    : parts_(std::move(parts)),
      planner_(planner),
      track_(track),
      afterFrame_(std::move(afterFrame)) {
  gst_segment_init(&sourceSegment_, GST_FORMAT_TIME);
  gst_segment_init(&videoSegment_, GST_FORMAT_TIME);
  videoPad_ = gst_element_get_static_pad(parts_.videoTail, "src");
  if (!videoPad_) {  // a tee: the file's branch is a pad of its own
    videoPad_ = gst_element_request_pad_simple(parts_.videoTail, "src_%u");
    videoPadRequested_ = true;
  }
  sourcePad_ = parts_.planPoint ? gst_element_get_static_pad(parts_.planPoint, "sink")
                                : GST_PAD(gst_object_ref(videoPad_));
  if (parts_.textTail) textPad_ = gst_element_get_static_pad(parts_.textTail, "src");
  // The frame must be planned (and its file opened) before it is routed:
  // on one pad, in one probe.
  if (videoPad_ == sourcePad_) {
    videoProbe_ =
        gst_pad_add_probe(videoPad_, kRelinkProbe, onSourceDataAndVideoOut, this, nullptr);
  } else {
    sourceProbe_ = gst_pad_add_probe(sourcePad_, kDataProbe, onSourceData, this, nullptr);
    videoProbe_ = gst_pad_add_probe(videoPad_, kRelinkProbe, onVideoOut, this, nullptr);
  }
  if (textPad_) textProbe_ = gst_pad_add_probe(textPad_, kRelinkProbe, onTextOut, this, nullptr);
}

SegmentWriter::~SegmentWriter() {
  if (textDrain_) g_source_remove(textDrain_);
  if (sourceProbe_) gst_pad_remove_probe(sourcePad_, sourceProbe_);
  gst_pad_remove_probe(videoPad_, videoProbe_);
  if (textProbe_) gst_pad_remove_probe(textPad_, textProbe_);
  if (videoPadRequested_) gst_element_release_request_pad(parts_.videoTail, videoPad_);
  for (GstPad* pad : {sourcePad_, videoPad_, textPad_})
    if (pad) gst_object_unref(pad);
  MutexLock lock(mutex_);
  files_.clear();
}

GstPadProbeReturn SegmentWriter::onSourceData(GstPad* pad, GstPadProbeInfo* info, gpointer data) {
  return static_cast<SegmentWriter*>(data)->planFrame(pad, info) ? GST_PAD_PROBE_OK
                                                                 : GST_PAD_PROBE_DROP;
}

GstPadProbeReturn SegmentWriter::onVideoOut(GstPad* pad, GstPadProbeInfo* info, gpointer data) {
  return static_cast<SegmentWriter*>(data)->routeFrame(pad, info);
}

GstPadProbeReturn SegmentWriter::onSourceDataAndVideoOut(GstPad* pad, GstPadProbeInfo* info,
                                                         gpointer data) {
  auto* self = static_cast<SegmentWriter*>(data);
  if (!self->planFrame(pad, info)) return GST_PAD_PROBE_DROP;
  return self->routeFrame(pad, info);
}

GstPadProbeReturn SegmentWriter::onTextOut(GstPad* pad, GstPadProbeInfo* info, gpointer data) {
  return static_cast<SegmentWriter*>(data)->routeText(pad, info);
}

bool SegmentWriter::noRoomFor(GstBuffer* frame) {
  DiskBudget* budget = parts_.disk.budget.get();
  if (!budget) return false;
  budget->countArrival();
  // A frame that depends on a dropped one would not decode: the drop goes
  // on to the next key frame. (The recorder's frames are JPEG here, each
  // a key frame, H.264 being encoded after this point; a source of
  // encoded frames is not.)
  bool key = !GST_BUFFER_FLAG_IS_SET(frame, GST_BUFFER_FLAG_DELTA_UNIT);
  dropping_ = budget->full() || (dropping_ && !key);
  if (dropping_) budget->countDrop();
  return dropping_;
}

bool SegmentWriter::planFrame(GstPad* pad, GstPadProbeInfo* info) {
  if (isEvent(info)) {
    keepSegment(info, sourceSegment_);
    return true;
  }
  GstBuffer* buffer = GST_PAD_PROBE_INFO_BUFFER(info);
  if (noRoomFor(buffer)) return false;
  GstClockTime time = runningTimeOf(sourceSegment_, buffer);
  if (!GST_CLOCK_TIME_IS_VALID(time)) return true;
  auto cut = planner_.onFrame(time, [this, time] { return unixMsOf(parts_.source, time); });
  // The encoder makes this very frame a key frame (the event travels just
  // ahead of it): at a cut, and every kKeyFrameInterval, whatever the frame
  // rate, because the muxer writes whole GOPs, which is what a crash loses.
  // The first frame is one anyway, and must not be asked for: x264enc
  // (GStreamer 1.22) measures that request against a segment it has not
  // set up yet, and then ignores every later one.
  if (cut == SegmentPlanner::Cut::kFirst) lastKeyFrame_ = time;
  bool due = time >= lastKeyFrame_ + kKeyFrameInterval;
  if (parts_.transcoded && (cut == SegmentPlanner::Cut::kNext || due)) {
    GstEvent* keyFrame = gst_video_event_new_downstream_force_key_unit(
        GST_BUFFER_PTS(buffer), GST_CLOCK_TIME_NONE, time, TRUE, 0);
    // Into the encoder's chain: ahead of the frame, on its thread.
    if (GST_PAD_IS_SINK(pad))
      gst_pad_send_event(pad, keyFrame);
    else
      gst_pad_push_event(pad, keyFrame);
    lastKeyFrame_ = time;
  }
  if (cut != SegmentPlanner::Cut::kNone) open(time);
  afterFrame_();
  return true;
}

void SegmentWriter::open(GstClockTime start) {
  auto planned = planner_.current();
  if (!planned) return;
  {
    MutexLock lock(mutex_);
    if (!addFile(*planned, start)) return;
  }
  // Its text goes out from now on (numbered as the files are). (Outside
  // the lock: the track holds its own while it pushes text, whose probe
  // takes this one: lock order.)
  track_.fileOpened(start);
}

bool SegmentWriter::addFile(const PlannedSegment& planned, GstClockTime start) {
  auto file = SegmentFile::open(parts_.pipeline, parts_.muxer, parts_.disk, planned.path, start,
                                opened_ + 1);
  if (!file) {
    // Its error is on the bus too, and the camera starts again.
    logLine(std::string(GST_OBJECT_NAME(parts_.pipeline)) + ": " + file.error());
    broken_ = true;
    return false;
  }
  ++opened_;
  // At a stop the text may end before the last frames have come through:
  // a file they open then has all the text it will get.
  if (textEnded_) (*file)->endText();
  files_.push_back(std::move(*file));
  return true;
}

// Ending and relinking happen under the lock: finished() (the main loop)
// deletes a file once both its inputs have ended, which may be at once.
// (The lock is never taken by a thread inside a muxer: ours are upstream.)
GstPadProbeReturn SegmentWriter::routeFrame(GstPad* pad, GstPadProbeInfo* info) {
  if (isEvent(info)) {
    keepSegment(info, videoSegment_);
    if (GST_EVENT_TYPE(GST_PAD_PROBE_INFO_EVENT(info)) != GST_EVENT_EOS) return GST_PAD_PROBE_PASS;
    track_.framesEnd();  // (outside the lock: the text's probe takes it)
    MutexLock lock(mutex_);
    for (const auto& file : files_) file->endVideoAtTheRunsEnd();
    return GST_PAD_PROBE_DROP;
  }
  GstBuffer* buffer = GST_PAD_PROBE_INFO_BUFFER(info);
  GstClockTime time = runningTimeOf(videoSegment_, buffer);
  uint64_t number;
  {
    MutexLock lock(mutex_);
    if (broken_ || !GST_CLOCK_TIME_IS_VALID(time)) return GST_PAD_PROBE_DROP;
    // The newest file that starts at or before this frame.
    SegmentFile* to = nullptr;
    for (const auto& file : files_)
      if (file->start() <= time) to = file.get();
    if (!to) return GST_PAD_PROBE_DROP;  // before the first file
    if (to != video_) {
      for (const auto& file : files_) {  // the frames of every file before are over
        if (file.get() == to) break;
        file->endVideo();
      }
      relink(pad, to->videoInput());
      video_ = to;
    }
    number = to->number();
  }
  planner_.addBytes(gst_buffer_get_size(buffer));
  // Last before the frame's push: what the text track has up to it.
  track_.beforeFrame(time, number);
  return GST_PAD_PROBE_PASS;
}

GstPadProbeReturn SegmentWriter::routeText(GstPad* pad, GstPadProbeInfo* info) {
  if (isEvent(info)) {
    if (GST_EVENT_TYPE(GST_PAD_PROBE_INFO_EVENT(info)) != GST_EVENT_EOS) return GST_PAD_PROBE_PASS;
    MutexLock lock(mutex_);
    textEnded_ = true;
    for (const auto& file : files_) file->endText();
    return GST_PAD_PROBE_DROP;
  }
  GstBuffer* buffer = GST_PAD_PROBE_INFO_BUFFER(info);
  if (!moveText(pad, TelemetryTrack::fileOf(buffer))) return GST_PAD_PROBE_DROP;
  if (!TelemetryTrack::isGap(buffer))
    return letLineIn(buffer) ? GST_PAD_PROBE_PASS : GST_PAD_PROBE_DROP;
  // (A GAP event comes through this probe again, as an event.)
  GstPadProbeReturn answer = TelemetryTrack::passGap(pad, info, parts_.muxer.textGapEvents);
  MutexLock lock(mutex_);
  if (text_) text_->afterLines();
  return answer;
}

bool SegmentWriter::letLineIn(GstBuffer* line) {
  MutexLock lock(mutex_);
  if (!text_ || !text_->takesTurns()) return true;
  // On the frames' thread (the lines go in just before a frame), which
  // keeps their segment.
  return text_->letLineIn(gst_segment_position_from_running_time(&videoSegment_, GST_FORMAT_TIME,
                                                                 GST_BUFFER_PTS(line)));
}

bool SegmentWriter::moveText(GstPad* pad, uint64_t number) {
  MutexLock lock(mutex_);
  if (text_ && text_->number() == number) return !text_->closed();
  SegmentFile* to = nullptr;
  for (const auto& file : files_)
    if (file->number() == number) to = file.get();
  // (A file that would not open, or a line late for a finished one.)
  if (!to || to->closed() || (text_ && text_->number() > number)) return false;
  for (const auto& file : files_) {  // the text of every file before is over
    if (file.get() == to) break;
    file->endText();
  }
  relink(pad, to->textInput());
  text_ = to;
  return true;
}

void SegmentWriter::end() {
  planner_.finishing();
  if (!parts_.textTail) return endFrames();
  // The frames end once the text's lines have all gone to the muxers: a
  // muxer finishes at the end of its frames, and lines not in by then
  // would be cut off. They go in with the next frame (TextOutlet::end);
  // with no frame for kTextDrain, at the frames' end.
  track_.end();
  textDrainEnds_ = std::chrono::steady_clock::now() + kTextDrain;
  textDrain_ = g_timeout_add(5, onTextDrainTick, this);
}

gboolean SegmentWriter::onTextDrainTick(gpointer self) {
  auto* writer = static_cast<SegmentWriter*>(self);
  if (!writer->track_.allSent() && std::chrono::steady_clock::now() < writer->textDrainEnds_)
    return G_SOURCE_CONTINUE;
  writer->textDrain_ = 0;
  writer->endFrames();
  return G_SOURCE_REMOVE;
}

void SegmentWriter::endFrames() {
  // Not gst_element_send_event(EOS): basesrc takes the stream lock for it,
  // and would hold the main loop for as long as a frame is held downstream.
  // wircsrc's signal returns nothing; appsrc's (a test's source) a flow
  // return, which needs somewhere to go (an extra argument is ignored).
  GstFlowReturn ignored = GST_FLOW_OK;
  g_signal_emit_by_name(parts_.source, "end-of-stream", &ignored);
}

void SegmentWriter::finished(const std::string& path, bool release) {
  std::unique_ptr<SegmentFile> file;
  {
    MutexLock lock(mutex_);
    finished_.push_back(path);
    if (!release) return;
    auto it = std::find_if(files_.begin(), files_.end(),
                           [&](const auto& candidate) { return candidate->path() == path; });
    if (it == files_.end()) return;
    file = std::move(*it);
    files_.erase(it);
    std::erase(finished_, path);
    if (video_ == file.get()) video_ = nullptr;
    if (text_ == file.get()) text_ = nullptr;
  }
  file.reset();  // out of the pipeline, outside the lock
}

std::vector<std::string> SegmentWriter::unfinished() const {
  MutexLock lock(mutex_);
  std::vector<std::string> paths;
  for (const auto& file : files_)
    if (std::find(finished_.begin(), finished_.end(), file->path()) == finished_.end())
      paths.push_back(file->path());
  return paths;
}

}  // namespace wircam::recorder
