#include "record/recording_index.h"

#include <algorithm>
#include <fstream>
#include <regex>

namespace wircam::recorder {

namespace fs = std::filesystem;

nlohmann::json toJson(const IndexEntry& e) {
  nlohmann::json j = {{"camera", e.camera},      {"file", e.file},
                      {"start_utc", e.startUtc}, {"duration_s", e.durationSeconds},
                      {"frames", e.frames},      {"bytes", e.bytes},
                      {"vehicle", e.vehicle}};
  if (!e.recorder.empty()) j["recorder"] = e.recorder;
  return j;
}

namespace {

std::optional<IndexEntry> entryOf(const nlohmann::json& j) {
  if (!j.is_object() || !j.contains("file") || !j["file"].is_string()) return std::nullopt;
  IndexEntry e;
  e.file = j["file"];
  e.camera = j.value("camera", "");
  e.startUtc = j.value("start_utc", "");
  e.durationSeconds = j.value("duration_s", 0.0);
  e.frames = j.value("frames", uint64_t{0});
  e.bytes = j.value("bytes", uint64_t{0});
  if (auto vehicle = j.find("vehicle"); vehicle != j.end() && vehicle->is_object())
    e.vehicle = *vehicle;
  e.recorder = j.value("recorder", "");
  return e;
}

bool isVideo(const fs::path& path) {
  return path.extension() == ".mkv" || path.extension() == ".mp4";
}

}  // namespace

std::optional<SegmentName> parseSegmentName(const std::string& file) {
  // "_N" when two start in one second ("-N" in recordings of earlier versions).
  static const std::regex kName(
      R"(^(.+)-(\d{4})(\d{2})(\d{2})T(\d{2})(\d{2})(\d{2})Z([-_]\d+)?\.(mkv|mp4)$)");
  std::smatch m;
  if (!std::regex_match(file, m, kName)) return std::nullopt;
  return SegmentName{m[1], m[2].str() + "-" + m[3].str() + "-" + m[4].str() + "T" + m[5].str() +
                               ":" + m[6].str() + ":" + m[7].str() + ".000Z"};
}

RecordingIndex::RecordingIndex(fs::path folder) : folder_(std::move(folder)) {
  std::ifstream in(path());
  if (!in) return;
  auto json = nlohmann::json::parse(in, nullptr, false);
  if (json.is_discarded() || !json.is_object() || !json["segments"].is_array()) return;
  for (const auto& item : json["segments"])
    if (auto entry = entryOf(item)) entries_.push_back(std::move(*entry));
}

size_t RecordingIndex::reconcile(const Inspector& inspect, const std::set<std::string>& open) {
  std::error_code error;
  std::erase_if(entries_,
                [&](const IndexEntry& e) { return !fs::exists(folder_ / e.file, error); });
  std::set<std::string> known;
  for (const auto& e : entries_) known.insert(e.file);
  std::vector<fs::path> missing;
  for (const auto& item : fs::directory_iterator(folder_, error)) {
    const auto& file = item.path();
    if (isVideo(file) && !known.count(file.filename().string()) && !open.count(file.string()))
      missing.push_back(file);
  }
  std::sort(missing.begin(), missing.end());
  size_t added = 0;
  for (const auto& file : missing) {
    auto entry = inspect(file);
    if (!entry) continue;
    add(std::move(*entry));
    ++added;
  }
  return added;
}

void RecordingIndex::add(IndexEntry entry) {
  remove(entry.file);
  // Oldest first; names of one camera sort by time, entries of all by start.
  auto at = std::upper_bound(
      entries_.begin(), entries_.end(), entry,
      [](const IndexEntry& a, const IndexEntry& b) { return a.startUtc < b.startUtc; });
  entries_.insert(at, std::move(entry));
}

void RecordingIndex::remove(const std::string& file) {
  std::erase_if(entries_, [&](const IndexEntry& e) { return e.file == file; });
}

bool RecordingIndex::save() const {
  nlohmann::json segments = nlohmann::json::array();
  for (const auto& e : entries_) segments.push_back(toJson(e));
  auto temporary = fs::path(path()).concat(".tmp");
  {
    std::ofstream out(temporary, std::ios::trunc);
    out << nlohmann::json{{"segments", segments}}.dump(1) << '\n';
    if (!out.flush()) return false;
  }
  std::error_code error;
  fs::rename(temporary, path(), error);
  return !error;
}

}  // namespace wircam::recorder
