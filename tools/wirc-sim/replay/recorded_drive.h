// A recorded drive to replay as a live vehicle: one camera's segments (one
// file, or a recordings folder's in index order), frame by frame, each with
// its time, and the battery its sidecars reported. Read with wirc-export's
// segment reader (GStreamer's demuxers; the frames' bytes untouched).
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common/expected.h"

namespace wircam::recorder {
class SegmentReader;
}

namespace wircam::sim {

class RecordedDrive {
 public:
  struct Frame {
    std::vector<uint8_t> jpeg;
    int64_t timeNs = 0;  // on the drive's timeline: a folder's UTC, a file's own
    int64_t ptsNs = 0;   // in its segment, as its sidecar's lines count
    std::string segment;
    uint64_t index = 0;  // in the drive, from 0
  };

  // `path`: a segment (.mkv of JPEG) or a folder of them; `camera` (as in
  // the file names) when the folder holds more than one. Errors: nothing
  // to replay, several cameras and none chosen, H.264 frames (the WiRC
  // protocol carries JPEG).
  static Expected<std::unique_ptr<RecordedDrive>, std::string> open(
      const std::filesystem::path& path, const std::string& camera = "");
  ~RecordedDrive();
  RecordedDrive(const RecordedDrive&) = delete;
  RecordedDrive& operator=(const RecordedDrive&) = delete;

  // The next frame, or nothing at the end. A segment that breaks off gives
  // its whole frames, then the next segment's (said in notes()).
  std::optional<Frame> next();
  // Back to the first frame (--loop).
  void rewind();
  // The battery last reported at or before `timeNs`; without any sidecar
  // line of it, a full 8.4 V.
  uint16_t batteryMillivoltsAt(int64_t timeNs) const;

  const std::string& camera() const { return camera_; }
  size_t segments() const { return segments_.size(); }
  // What the user should know, each said once: segments left out or broken
  // off, a drive without battery reports.
  std::vector<std::string> takeNotes();
  // The segments skipped or cut short, and how ("x.mkv: played 30 whole
  // frames; the file ends mid-frame"), for the replay's summary.
  const std::vector<std::string>& damage() const { return damage_; }

 private:
  struct Segment {
    std::filesystem::path video;
    int64_t startNs = 0;
  };
  RecordedDrive() = default;
  void readBattery();
  void damaged(std::string what);

  std::string camera_;
  std::vector<Segment> segments_;
  size_t first_ = 0;  // the first segment with a readable frame
  size_t current_ = 0;
  std::unique_ptr<recorder::SegmentReader> reader_;
  uint64_t framesInSegment_ = 0, framesRead_ = 0;
  std::vector<std::pair<int64_t, uint16_t>> battery_;  // (time, mV), in time order
  std::vector<std::string> notes_;
  std::vector<std::string> damage_;
};

}  // namespace wircam::sim
