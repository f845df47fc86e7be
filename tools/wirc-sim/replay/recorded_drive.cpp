#include "replay/recorded_drive.h"

#include <gst/gst.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <set>

#include "gst_scoped.h"
#include "record/recording_index.h"
#include "recording/cut_segment.h"
#include "recording/segment_reader.h"
#include "recording/segment_selection.h"

namespace wircam::sim {

namespace fs = std::filesystem;

namespace {

constexpr uint16_t kFullBatteryMv = 8400;

// The cameras whose segments are in `folder`, from the file names.
std::set<std::string> camerasIn(const fs::path& folder) {
  std::set<std::string> cameras;
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(folder, error))
    if (auto name = recorder::parseSegmentName(entry.path().filename().string()))
      cameras.insert(name->camera);
  return cameras;
}

bool isJpeg(GstCaps* caps) {
  return caps && gst_structure_has_name(gst_caps_get_structure(caps, 0), "image/jpeg");
}

std::string mediaTypeOf(GstCaps* caps) {
  return caps ? gst_structure_get_name(gst_caps_get_structure(caps, 0)) : "nothing";
}

}  // namespace

RecordedDrive::~RecordedDrive() = default;

Expected<std::unique_ptr<RecordedDrive>, std::string> RecordedDrive::open(
    const fs::path& path, const std::string& camera) {
  std::unique_ptr<RecordedDrive> drive(new RecordedDrive);
  std::error_code error;
  if (fs::is_regular_file(path, error)) {
    // One file on its own timeline: its frames' times are its pts.
    auto name = recorder::parseSegmentName(path.filename().string());
    drive->camera_ = name ? name->camera : path.stem().string();
    drive->segments_.push_back({path, 0});
  } else if (fs::is_directory(path, error)) {
    drive->camera_ = camera;
    if (camera.empty()) {
      auto cameras = camerasIn(path);
      if (cameras.empty()) return unexpected("no recordings in " + path.string());
      if (cameras.size() > 1) {
        std::string names;
        for (const auto& name : cameras) names += (names.empty() ? "" : ", ") + name;
        return unexpected(path.string() + " holds several cameras (" + names +
                          "): choose one with --camera");
      }
      drive->camera_ = *cameras.begin();
    }
    auto selection = recorder::selectSegments(path, drive->camera_, std::nullopt, std::nullopt);
    if (!selection) return unexpected(selection.error());
    for (const auto& segment : selection->segments)
      drive->segments_.push_back({segment.video, segment.startNs});
    drive->notes_ = std::move(selection->notes);
  } else {
    return unexpected("no such file or folder: " + path.string());
  }
  // The WiRC protocol carries JPEG: an H.264 recording cannot be replayed.
  // The first segment with a frame tells; those before it that cannot be
  // read (zeros, empty, not a recording) are skipped, said.
  for (; drive->first_ < drive->segments_.size(); ++drive->first_) {
    const auto& video = drive->segments_[drive->first_].video;
    auto reader = recorder::SegmentReader::open(video);
    std::string problem = reader ? "" : reader.error();
    if (reader) {
      auto frame = (*reader)->next();
      if (frame && *frame) {
        if (!isJpeg((*reader)->caps()))
          return unexpected(video.filename().string() + " holds " + mediaTypeOf((*reader)->caps()) +
                            ": the WiRC protocol carries JPEG frames, so only recordings made "
                            "with --codec jpeg (the default) can be replayed");
        break;
      }
      problem = frame ? "no frame in it" : frame.error();
    }
    drive->damaged(video.filename().string() + ": skipped (" + problem + ")");
  }
  if (drive->first_ == drive->segments_.size()) {
    std::string why;
    for (const auto& damage : drive->damage_) why += "; " + damage;
    return unexpected(path.string() + " holds no readable frame" + why);
  }
  drive->current_ = drive->first_;
  drive->readBattery();
  return drive;
}

void RecordedDrive::readBattery() {
  for (const auto& segment : segments_)
    for (const auto& text : recorder::sidecarLines(segment.video)) {
      auto line = nlohmann::json::parse(text, nullptr, false);
      if (!line.is_object() || !line.contains("battery-v") || !line["battery-v"].is_number())
        continue;
      double volts = line["battery-v"];
      if (volts < 0 || volts > 60) continue;
      battery_.emplace_back(segment.startNs + line.value("pts", int64_t{0}),
                            static_cast<uint16_t>(std::lround(volts * 1000)));
    }
  std::stable_sort(battery_.begin(), battery_.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  if (battery_.empty())
    notes_.push_back("no battery reports in the sidecars: the status says a full 8.4 V");
}

uint16_t RecordedDrive::batteryMillivoltsAt(int64_t timeNs) const {
  auto after = std::upper_bound(battery_.begin(), battery_.end(), timeNs,
                                [](int64_t t, const auto& report) { return t < report.first; });
  if (after == battery_.begin()) return battery_.empty() ? kFullBatteryMv : after->second;
  return std::prev(after)->second;
}

std::optional<RecordedDrive::Frame> RecordedDrive::next() {
  while (current_ < segments_.size()) {
    const auto& segment = segments_[current_];
    std::string name = segment.video.filename().string();
    if (!reader_) {
      auto opened = recorder::SegmentReader::open(segment.video);
      if (!opened) {
        damaged(name + ": skipped (" + opened.error() + ")");
        ++current_;
        continue;
      }
      reader_ = std::move(*opened);
      framesInSegment_ = 0;
    }
    auto frame = reader_->next();
    // The segment's end, a break in it, or frames the protocol cannot carry:
    // on to the next segment (all but a whole file's end said).
    std::optional<std::string> skipped;
    if (!frame)
      skipped = framesInSegment_ ? "played " + std::to_string(framesInSegment_) +
                                       " frames, then: " + frame.error()
                                 : "skipped (" + frame.error() + ")";
    else if (*frame && !isJpeg(reader_->caps()))
      skipped = "holds " + mediaTypeOf(reader_->caps()) + ": skipped";
    else if (!*frame && recorder::endsMidElement(segment.video))
      skipped =
          "played " + std::to_string(framesInSegment_) + " whole frames; the file ends mid-frame";
    if (skipped) damaged(name + ": " + *skipped);
    if (skipped || !*frame) {
      reader_.reset();
      ++current_;
      continue;
    }
    ++framesInSegment_;
    Frame out;
    if (gst::ScopedBufferMap map((*frame)->buffer, GST_MAP_READ); map)
      out.jpeg.assign(map.data(), map.data() + map.size());
    out.ptsNs = (*frame)->ptsNs;
    out.timeNs = segment.startNs + out.ptsNs;
    out.segment = name;
    out.index = framesRead_++;
    return out;
  }
  return std::nullopt;
}

void RecordedDrive::damaged(std::string what) {
  // Said once, however often --loop passes it.
  if (std::find(damage_.begin(), damage_.end(), what) != damage_.end()) return;
  notes_.push_back(what);
  damage_.push_back(std::move(what));
}

void RecordedDrive::rewind() {
  reader_.reset();
  current_ = first_;
  framesRead_ = 0;
}

std::vector<std::string> RecordedDrive::takeNotes() { return std::exchange(notes_, {}); }

}  // namespace wircam::sim
