#include "http_routes.h"

namespace wircam::recorder {

namespace {

constexpr std::string_view kLive = "/live/";
constexpr std::string_view kMjpeg = ".mjpg";
constexpr std::string_view kRecordings = "/recordings/";
constexpr std::string_view kCameras = "/api/cameras/";
constexpr std::string_view kSnapshot = "/snapshot.jpg";

}  // namespace

Route routeOf(std::string_view path) {
  using Kind = Route::Kind;
  if (path == "/" || path == "/index.html") return {Kind::Page, ""};
  if (path == "/api/status") return {Kind::Status, ""};
  if (path == "/api/events") return {Kind::Events, ""};
  if (path == "/api/cameras") return {Kind::Cameras, ""};
  if (path == "/api/recordings") return {Kind::RecordingIndex, ""};
  if (path.starts_with(kCameras) && path.ends_with(kSnapshot) &&
      path.size() > kCameras.size() + kSnapshot.size()) {
    auto camera = path.substr(kCameras.size(), path.size() - kCameras.size() - kSnapshot.size());
    if (camera.find('/') == std::string_view::npos) return {Kind::Snapshot, std::string(camera)};
  }
  if (path.starts_with("/api/")) return {Kind::ApiNotFound, ""};
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
