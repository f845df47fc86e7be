#include "export/exporter.h"

#include <algorithm>
#include <cstring>
#include <fstream>
#include <memory>

#include "export/mcap_export.h"
#include "export/muxed_export.h"
#include "recording/cut_segment.h"
#include "recording/segment_reader.h"

namespace wircam::recorder {

namespace fs = std::filesystem;

std::optional<ExportFormat> exportFormatOf(const std::string& name) {
  if (name == "mkv") return ExportFormat::kMkv;
  if (name == "mp4") return ExportFormat::kMp4;
  if (name == "mcap") return ExportFormat::kMcap;
  return std::nullopt;
}

const char* exportFormatName(ExportFormat format) {
  switch (format) {
    case ExportFormat::kMkv:
      return "mkv";
    case ExportFormat::kMp4:
      return "mp4";
    case ExportFormat::kMcap:
      return "mcap";
  }
  return "mkv";
}

namespace {

struct TimedLine {
  int64_t utcNs;
  nlohmann::json json;
};

// A line's own time: its "utc", which the recorder writes as it happens
// (lines of an outage come before the next segment's first frame); the
// segment's start plus its "pts" for lines without one.
int64_t utcOf(const nlohmann::json& line, const ExportSegment& segment) {
  if (line.contains("utc") && line["utc"].is_string())
    if (auto utc = parseIsoTime(line["utc"].get<std::string>())) return *utc;
  return segment.startNs + std::max<int64_t>(line.value("pts", int64_t{0}), 0);
}

// A segment's sidecar lines at their UTC (its start plus their "pts"), in
// time order; lines that do not parse are left out.
std::vector<TimedLine> linesOf(const ExportSegment& segment) {
  std::vector<TimedLine> lines;
  for (const auto& text : sidecarLines(segment.video)) {
    auto json = nlohmann::json::parse(text, nullptr, false);
    if (!json.is_object()) continue;
    lines.push_back({utcOf(json, segment), std::move(json)});
  }
  std::stable_sort(lines.begin(), lines.end(),
                   [](const auto& a, const auto& b) { return a.utcNs < b.utcNs; });
  return lines;
}

// Whether one segment's frames can follow another's in one file: the same
// codec, size and codec data. The frame rate is left out: the MP4 demuxer
// guesses it from each file's sample durations, which vary a little.
bool sameFrames(GstCaps* a, GstCaps* b) {
  GstCaps* first = gst_caps_copy(a);
  GstCaps* second = gst_caps_copy(b);
  for (GstCaps* caps : {first, second})
    gst_structure_remove_field(gst_caps_get_structure(caps, 0), "framerate");
  bool same = gst_caps_is_equal(first, second);
  gst_caps_unref(first);
  gst_caps_unref(second);
  return same;
}

// Feeds the sink in time order and keeps the timeline: from 0 at the first
// frame, each frame after the one before.
class Timeline {
 public:
  // `jsonl`: where the lines go as well (none when streamed); `onFirst`:
  // told the first frame's time, before the sink has it.
  Timeline(ExportSink& sink, std::ofstream* jsonl, const ExportRequest& request,
           std::function<void(int64_t)> onFirst)
      : sink_(sink), jsonl_(jsonl), request_(request), onFirst_(std::move(onFirst)) {}

  bool inRange(int64_t utcNs) const {
    return (!request_.start || utcNs >= *request_.start) &&
           (!request_.end || utcNs <= *request_.end);
  }

  std::optional<ExportError> frame(GstBuffer* buffer, int64_t utcNs, bool key, GstCaps* caps,
                                   const std::string& recorder) {
    if (!origin_) {
      onFirst_(utcNs);
      // The format cannot hold these frames (JPEG in MP4), or its muxer is missing.
      if (auto problem = sink_.start(caps))
        return ExportError{ExportError::Kind::kUnsupported, *problem};
      origin_ = utcNs;
      report.firstUtcNs = utcNs;
    }
    // Each frame at its own time. Where that would not rise (a segment's
    // start from a rebuilt index may be known to its name's second only),
    // a frame follows the one before by the frames' last real interval:
    // players count in frames. Only intervals between frames count, never
    // an outage's gap, so the frames after a gap keep their own times.
    if (lastUtc_ && utcNs > *lastUtc_ && utcNs - *lastUtc_ <= kLongestFrameInterval)
      step_ = utcNs - *lastUtc_;
    int64_t pts = lastFrame_ < 0 ? 0 : std::max(utcNs - *origin_, lastFrame_ + step_);
    lastFrame_ = pts;
    lastUtc_ = utcNs;
    lastRecorder_ = recorder;
    report.lastUtcNs = utcNs;
    ++report.frames;
    return failed(sink_.frame(buffer, pts, utcNs, key));
  }

  std::optional<ExportError> line(TimedLine& line) {
    if (!origin_) return std::nullopt;  // lines before the first frame wait for it
    int64_t pts = std::max<int64_t>(line.utcNs - *origin_, 0);
    line.json["pts"] = pts;
    if (jsonl_) *jsonl_ << line.json.dump() << '\n';
    ++report.lines;
    return failed(sink_.line(line.json, pts, line.utcNs));
  }

  bool started() const { return origin_.has_value(); }
  // A frame at `utcNs` of a segment from `recorder` that has given the
  // export no frame yet would repeat a moment already exported: another
  // recorder's, no later than half a frame after the last one (two
  // recorders stamp one frame of the device each on its own arrival,
  // microseconds apart). The same recorder's next segment, and the rest of
  // a segment once its frames are taken, follow in time: none repeats,
  // however close two came (a sender late for one frame and on time for
  // the next).
  bool repeats(int64_t utcNs, const std::string& recorder) const {
    return request_.overlapping && lastUtc_ && recorder != lastRecorder_ &&
           utcNs < *lastUtc_ + step_ / 2;
  }
  ExportReport report;

 private:
  static std::optional<ExportError> failed(std::optional<std::string> problem) {
    if (!problem) return std::nullopt;
    return ExportError{ExportError::Kind::kFailed, *problem};
  }

  ExportSink& sink_;
  std::ofstream* jsonl_;
  const ExportRequest& request_;
  std::function<void(int64_t)> onFirst_;
  std::optional<int64_t> origin_;
  static constexpr int64_t kLongestFrameInterval = 1000000000;  // 1 fps
  int64_t lastFrame_ = -1;
  std::optional<int64_t> lastUtc_;
  std::string lastRecorder_;        // whose segment the last frame came from
  int64_t step_ = 1000000000 / 15;  // the frames' last real interval
};

// The frames of one segment and its lines, merged by time.
std::optional<ExportError> exportSegment(const ExportSegment& segment, Timeline& timeline,
                                         GstCaps*& caps, std::vector<std::string>& notes,
                                         const std::function<bool()>& onFrame) {
  std::string name = segment.video.filename().string();
  auto reader = SegmentReader::open(segment.video);
  if (!reader) {
    notes.push_back(name + ": " + reader.error() + ": skipped");
    return std::nullopt;
  }
  auto lines = linesOf(segment);
  // Lines from before the segment's first frame (its login) wait for it.
  std::vector<TimedLine> waiting;
  size_t nextLine = 0;
  uint64_t frames = 0;
  bool whole = false;  // read to its end: its lines after the last frame belong to it
  bool afterRepeats = false;
  bool taking = false;  // a frame of this segment is in the export
  while (true) {
    auto frame = (*reader)->next();
    if (!frame) {
      notes.push_back(frames
                          ? name + ": broken off after " + std::to_string(frames) + " frames (" +
                                frame.error() + "): the rest skipped"
                          : name + ": skipped (not a readable recording: " + frame.error() + ")");
      break;
    }
    if (!*frame) {
      whole = !endsMidElement(segment.video);
      if (!whole)
        notes.push_back(name + ": " + std::to_string(frames) +
                        " whole frames; the file ends mid-frame");
      break;
    }
    if (frames++ == 0 && caps && !sameFrames(caps, (*reader)->caps())) {
      notes.push_back(
          name + ": its frames differ from the first segment's (" +
          std::string(gst_structure_get_name(gst_caps_get_structure((*reader)->caps(), 0))) +
          "): skipped");
      return std::nullopt;
    }
    int64_t utc = segment.startNs + (*frame)->ptsNs;
    for (; nextLine < lines.size() && lines[nextLine].utcNs <= utc; ++nextLine)
      if (timeline.inRange(lines[nextLine].utcNs)) waiting.push_back(std::move(lines[nextLine]));
    if (!timeline.inRange(utc)) continue;
    if (!taking && timeline.repeats(utc, segment.recorder)) {
      // So are its lines: the other recorder's of that moment are in.
      afterRepeats = true;
      waiting.clear();
      continue;
    }
    // H.264 begins on a key frame: the ones before it could not be decoded
    // (every JPEG frame is one); so does the rest of a segment whose first
    // frames repeated another's (another recorder's encoder made them).
    if ((!timeline.started() || afterRepeats) && !(*frame)->key) continue;
    afterRepeats = false;
    if (!caps) caps = gst_caps_ref((*reader)->caps());
    if (auto problem = timeline.frame((*frame)->buffer, utc, (*frame)->key, caps, segment.recorder))
      return problem;
    taking = true;
    if (!onFrame()) return std::nullopt;  // stopped: the caller knows
    for (auto& line : waiting)
      if (auto problem = timeline.line(line)) return problem;
    waiting.clear();
  }
  // The lines after the last frame, up to the segment's end; of a segment
  // broken off or cut short, they tell of frames the export does not hold.
  if (timeline.started() && whole && !afterRepeats) {
    for (; nextLine < lines.size(); ++nextLine)
      if (timeline.inRange(lines[nextLine].utcNs)) waiting.push_back(std::move(lines[nextLine]));
    for (auto& line : waiting)
      if (auto problem = timeline.line(line)) return problem;
  }
  return std::nullopt;
}

// The sink for the request's format, to its file or its stream.
std::unique_ptr<ExportSink> sinkFor(const ExportRequest& request, const fs::path& writing) {
  ExportTarget target{request.stream >= 0 ? request.out.string() : writing.string(),
                      request.stream};
  if (request.format == ExportFormat::kMcap)
    return std::make_unique<McapExport>(target, request.camera);
  return std::make_unique<MuxedExport>(target, exportFormatName(request.format));
}

// Where the range ends as planned: its end, or the last segment's.
int64_t plannedEnd(const ExportRequest& request, const ExportSelection& selection) {
  int64_t last = 0;
  for (const auto& segment : selection.segments)
    last = std::max(last, segment.startNs + segment.durationNs);
  return request.end ? std::min(*request.end, last) : last;
}

}  // namespace

Expected<ExportReport, ExportError> exportRange(const ExportRequest& request,
                                                const ExportProgress& progress,
                                                const ExportStarted& started) {
  using Kind = ExportError::Kind;
  auto selection = selectSegments(request.recordings, request.camera, request.start, request.end);
  if (!selection) return unexpected(ExportError{Kind::kNothing, selection.error()});
  bool streamed = request.stream >= 0;
  // Written beside under other names, and renamed only once whole: an
  // export that fails or is stopped leaves the files of an earlier one as
  // they were.
  fs::path jsonlPath = fs::path(request.out).replace_extension(".jsonl");
  fs::path writing = partialPathOf(request.out), writingJsonl = partialPathOf(jsonlPath);
  auto sink = sinkFor(request, writing);
  std::ofstream jsonl;
  if (!streamed) {
    jsonl.open(writingJsonl);
    if (!jsonl)  // the first file opened: most often --out's folder is missing or read-only
      return unexpected(ExportError{Kind::kFailed, "cannot write " + request.out.string() +
                                                       " (nor " + jsonlPath.filename().string() +
                                                       " beside it): " + std::strerror(errno)});
  }

  Timeline timeline(*sink, streamed ? nullptr : &jsonl, request, [&](int64_t firstUtcNs) {
    if (started) started({firstUtcNs, plannedEnd(request, *selection), selection->notes});
  });
  uint64_t total = 0, done = 0;
  for (const auto& segment : selection->segments) total += segment.frames;
  GstCaps* caps = nullptr;
  std::optional<ExportError> problem;
  for (const auto& segment : selection->segments) {
    bool stopped = false;
    uint64_t framesBefore = timeline.report.frames;
    problem = exportSegment(segment, timeline, caps, selection->notes, [&] {
      if (progress && ++done % 50 == 0 && !progress(done, total, sink->bytesWritten()))
        stopped = true;
      return !stopped;
    });
    if (stopped) problem = ExportError{Kind::kCancelled, "the export was stopped"};
    if (problem) break;
    if (timeline.report.frames > framesBefore) ++timeline.report.segments;
  }
  if (caps) gst_caps_unref(caps);
  if (!problem && !timeline.started())
    problem =
        ExportError{Kind::kNothing, "camera " + request.camera + " has no frame in that range"};
  if (!problem && timeline.started())
    if (auto failed = sink->finish()) problem = ExportError{Kind::kFailed, *failed};
  uint64_t bytes = sink->bytesWritten();
  sink.reset();
  std::error_code error;
  if (!streamed) {
    jsonl.close();
    if (!problem) {
      fs::rename(writing, request.out, error);
      if (!error) fs::rename(writingJsonl, jsonlPath, error);
      if (error)
        problem = ExportError{Kind::kFailed,
                              "cannot write " + request.out.string() + ": " + error.message()};
    }
    if (problem) {
      fs::remove(writing, error);
      fs::remove(writingJsonl, error);
    }
  }
  if (problem) return unexpected(*problem);
  if (progress) progress(total, total, bytes);
  timeline.report.notes = std::move(selection->notes);
  return timeline.report;
}

fs::path partialPathOf(const fs::path& out) { return out.string() + ".partial"; }

std::string compactTimeOf(int64_t unixNs) {
  std::string compact;
  for (char c : isoTimeOf(unixNs)) {
    if (c == '.') break;
    if (c != '-' && c != ':') compact += c;
  }
  return compact + "Z";
}

std::string fileNamePart(const std::string& text) {
  std::string part;
  for (char c : text) part += g_ascii_isalnum(c) || c == '-' || c == '.' ? c : '_';
  return part;
}

}  // namespace wircam::recorder
