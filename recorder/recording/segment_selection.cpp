#include "recording/segment_selection.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <nlohmann/json.hpp>
#include <set>

#include "common/printable_text.h"
#include "record/recording_index.h"
#include "record/segment_inspector.h"
#include "recording/segment_reader.h"

namespace wircam::recorder {

// A segment file the index lacks, written to this recently, is taken for
// the one a recorder is writing now.
constexpr auto kStillWritten = std::chrono::seconds(30);

namespace fs = std::filesystem;

std::optional<int64_t> parseIsoTime(const std::string& text) {
  std::tm tm{};
  int consumed = 0;
  if (std::sscanf(text.c_str(), "%4d-%2d-%2dT%2d:%2d:%2d%n", &tm.tm_year, &tm.tm_mon, &tm.tm_mday,
                  &tm.tm_hour, &tm.tm_min, &tm.tm_sec, &consumed) != 6 ||
      consumed != 19)
    return std::nullopt;
  // A day the month has (February 30 was taken as March 2).
  static constexpr int kDays[] = {31, 29, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  bool leap = tm.tm_year % 4 == 0 && (tm.tm_year % 100 != 0 || tm.tm_year % 400 == 0);
  if (tm.tm_mon < 1 || tm.tm_mon > 12 || tm.tm_mday < 1 || tm.tm_mday > kDays[tm.tm_mon - 1] ||
      (tm.tm_mon == 2 && tm.tm_mday == 29 && !leap) || tm.tm_hour > 23 || tm.tm_min > 59 ||
      tm.tm_sec > 60)
    return std::nullopt;
  std::string rest = text.substr(19);
  int64_t fraction = 0;
  if (!rest.empty() && rest[0] == '.') {
    size_t digits = 1;
    int64_t scale = 100000000;
    // Any number of digits (ISO 8601 sets no limit); past nanoseconds cut.
    while (digits < rest.size() && std::isdigit(static_cast<unsigned char>(rest[digits]))) {
      fraction += (rest[digits] - '0') * scale;
      scale /= 10;
      ++digits;
    }
    if (digits == 1) return std::nullopt;
    rest = rest.substr(digits);
  }
  tm.tm_year -= 1900;
  tm.tm_mon -= 1;
  int64_t seconds;
  if (rest == "Z") {
    seconds = timegm(&tm);
  } else if (rest.empty()) {
    tm.tm_isdst = -1;
    seconds = std::mktime(&tm);
  } else {
    int hours = 0, minutes = 0;
    char sign = rest[0];
    if ((sign != '+' && sign != '-') ||
        std::sscanf(rest.c_str() + 1, "%2d:%2d%n", &hours, &minutes, &consumed) != 2 ||
        consumed != 5 || static_cast<size_t>(consumed) + 1 != rest.size() || hours > 23 ||
        minutes > 59)
      return std::nullopt;
    seconds = timegm(&tm) - (sign == '+' ? 1 : -1) * (hours * 3600 + minutes * 60);
  }
  return seconds * 1000000000 + fraction;
}

std::string isoTimeOf(int64_t unixNs) {
  std::time_t seconds = static_cast<std::time_t>(std::floor(unixNs / 1e9));
  int millis = static_cast<int>((unixNs - seconds * 1000000000LL) / 1000000);
  std::tm tm{};
  gmtime_r(&seconds, &tm);
  char text[64];
  std::snprintf(text, sizeof text, "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ", tm.tm_year + 1900,
                tm.tm_mon + 1, tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec, millis);
  return text;
}

namespace {

// A segment's first frame to the millisecond, from its sidecar: a line's
// UTC less its time in the file (a rebuilt index knows only its name's
// second).
std::optional<int64_t> startFromSidecar(const fs::path& video) {
  for (const auto& text : sidecarLines(video)) {
    auto line = nlohmann::json::parse(text, nullptr, false);
    if (!line.is_object() || line.value("pts", int64_t{0}) <= 0 || !line["utc"].is_string())
      continue;
    auto utc = parseIsoTime(line["utc"].get<std::string>());
    if (utc) return *utc - line["pts"].get<int64_t>();
  }
  return std::nullopt;
}

}  // namespace

Expected<ExportSelection, std::string> selectSegments(const fs::path& folder,
                                                      const std::string& camera,
                                                      std::optional<int64_t> start,
                                                      std::optional<int64_t> end) {
  std::error_code error;
  if (!fs::is_directory(folder, error))
    return unexpected("no recordings folder " + folder.string());
  ExportSelection selection;
  RecordingIndex index(folder);
  if (!fs::exists(index.path())) {
    // As at the recorder's start-up: every file read back.
    size_t added = index.reconcile(inspectSegment);
    selection.notes.push_back("no " + std::string(RecordingIndex::kFileName) + ": rebuilt from " +
                              std::to_string(added) + " files");
  }
  bool rebuilt = !selection.notes.empty();
  std::set<std::string> cameras, indexed;
  for (const auto& entry : index.entries()) {
    cameras.insert(entry.camera);
    indexed.insert(entry.file);
    if (entry.camera != camera) continue;
    auto begins = rebuilt ? startFromSidecar(folder / entry.file) : std::nullopt;
    if (!begins) begins = parseIsoTime(entry.startUtc);
    if (!begins) continue;
    auto lasts = static_cast<int64_t>(entry.durationSeconds * 1e9);
    if ((end && *begins > *end) || (start && *begins + lasts < *start)) continue;
    selection.segments.push_back(
        {folder / entry.file, *begins, lasts, entry.frames, entry.recorder});
  }
  // A file of the camera the index lacks: still being written (the recorder
  // indexes each as it closes, and writes the open one at least every
  // cluster), unreadable when the index was rebuilt just now, or put there
  // by hand or left by a recorder that was killed: read back like a rebuilt
  // index's.
  std::string beingWritten;
  for (const auto& file : fs::directory_iterator(folder, error)) {
    std::string filename = file.path().filename().string();
    auto name = parseSegmentName(filename);
    if (!name || name->camera != camera || indexed.count(filename)) continue;
    if (rebuilt) {
      selection.notes.push_back(filename + " holds no readable frame: skipped");
      continue;
    }
    auto written = fs::last_write_time(file.path(), error);
    if (!error && fs::file_time_type::clock::now() - written < kStillWritten) {
      selection.notes.push_back(filename + " is still being written: not exported");
      beingWritten = filename;
      continue;
    }
    auto entry = inspectSegment(file.path());
    auto begins = entry ? parseIsoTime(entry->startUtc) : std::nullopt;
    if (!entry || !begins) {
      selection.notes.push_back(filename + " holds no readable frame: skipped");
      continue;
    }
    auto lasts = static_cast<int64_t>(entry->durationSeconds * 1e9);
    if ((end && *begins > *end) || (start && *begins + lasts < *start)) continue;
    cameras.insert(camera);
    selection.segments.push_back({file.path(), *begins, lasts, entry->frames});
    selection.notes.push_back(filename + " is not in " + std::string(RecordingIndex::kFileName) +
                              ": read back and exported");
  }
  // The name as asked for, which may be anything (a query's 50 KB went
  // whole into the answer and the log): its start, printable.
  std::string asked =
      printableText(std::string_view(camera).substr(0, 80)) + (camera.size() > 80 ? "…" : "");
  if (!cameras.count(camera) && !beingWritten.empty())
    return unexpected("camera " + asked + " has no finished segment yet: " + beingWritten +
                      " is still being written");
  if (!cameras.count(camera)) {
    std::string known;
    for (const auto& name : cameras) known += (known.empty() ? "" : ", ") + name;
    return unexpected("no camera " + asked + " in " + folder.string() +
                      (known.empty() ? " (no finished segments)" : " (there are: " + known + ")"));
  }
  if (selection.segments.empty())
    return unexpected("camera " + asked + " has no frame in that range");
  std::sort(selection.segments.begin(), selection.segments.end(),
            [](const auto& a, const auto& b) { return a.startNs < b.startNs; });
  return selection;
}

}  // namespace wircam::recorder
