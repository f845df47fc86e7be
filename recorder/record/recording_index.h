// The index of a recordings folder: one entry per finished segment, kept in
// `<folder>/index.json` ({"segments":[...]}, oldest first) so that the web
// interface, fleet tools and scripts find recordings without opening them.
// Updated as each segment closes; files it lacks (a crash's open segment,
// a lost index) are read back and added, entries of deleted files dropped.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace wircam::recorder {

struct IndexEntry {
  std::string camera;    // the stream: "<device>-cam<N>"
  std::string file;      // the video's name inside the folder
  std::string startUtc;  // ISO 8601, Z
  double durationSeconds = 0;
  uint64_t frames = 0;
  uint64_t bytes = 0;
  // The vehicle as the device named itself ({"name", "serial"}), or null.
  nlohmann::json vehicle;
  // The fleet's recorder it was fetched from (a fleet export's folder),
  // or empty: one recorder's segments never overlap, two recorders' may.
  std::string recorder;
};

nlohmann::json toJson(const IndexEntry& entry);

// What a file's name says: its camera and UTC start, if it is a segment
// named "<camera>-YYYYMMDDTHHMMSSZ[-N].mkv|.mp4".
struct SegmentName {
  std::string camera;
  std::string startUtc;
};
std::optional<SegmentName> parseSegmentName(const std::string& file);

class RecordingIndex {
 public:
  static constexpr const char* kFileName = "index.json";
  // Reads the folder's index; an unreadable one counts as missing.
  explicit RecordingIndex(std::filesystem::path folder);

  // Reads a segment file the index lacks (its frames and duration).
  using Inspector = std::function<std::optional<IndexEntry>(const std::filesystem::path&)>;
  // Adds the video files of the folder the index lacks, except `open` ones
  // (being written), and drops entries whose file is gone. Returns how
  // many entries were added.
  size_t reconcile(const Inspector& inspect, const std::set<std::string>& open = {});

  void add(IndexEntry entry);  // replaces an entry for the same file
  void remove(const std::string& file);
  // Written to a temporary file and renamed: readers never see half of it.
  bool save() const;

  const std::vector<IndexEntry>& entries() const { return entries_; }
  std::filesystem::path path() const { return folder_ / kFileName; }

 private:
  std::filesystem::path folder_;
  std::vector<IndexEntry> entries_;
};

}  // namespace wircam::recorder
