#include "http_routes.h"

namespace wircam::recorder {

namespace {

constexpr std::string_view kLive = "/live/";
constexpr std::string_view kMjpeg = ".mjpg";
constexpr std::string_view kRecordings = "/recordings/";

}  // namespace

Route routeOf(std::string_view path) {
  using Kind = Route::Kind;
  if (path == "/" || path == "/index.html") return {Kind::Page, ""};
  if (path == "/api/status") return {Kind::Status, ""};
  if (path == "/api/events") return {Kind::Events, ""};
  if (path.starts_with(kLive) && path.ends_with(kMjpeg) &&
      path.size() > kLive.size() + kMjpeg.size())
    return {Kind::Live,
            std::string(path.substr(kLive.size(), path.size() - kLive.size() - kMjpeg.size()))};
  if (path == "/recordings" || path == kRecordings) return {Kind::RecordingList, ""};
  if (path.starts_with(kRecordings))
    return {Kind::Recording, std::string(path.substr(kRecordings.size()))};
  return {Kind::NotFound, ""};
}

const char* recordingContentType(std::string_view name) {
  if (name.ends_with(".mkv")) return "video/x-matroska";
  if (name.ends_with(".mp4")) return "video/mp4";
  if (name.ends_with(".jsonl")) return "application/x-ndjson";
  return nullptr;
}

bool isRecordingName(std::string_view name) {
  return !name.empty() && name.front() != '.' && name.find('/') == std::string_view::npos &&
         name.find('\0') == std::string_view::npos && recordingContentType(name) != nullptr;
}

}  // namespace wircam::recorder
