// HttpServer's recordings: snapshots of the live cameras, the index, the
// files themselves (downloads, ranges) and their deletion.
#include <algorithm>
#include <filesystem>
#include <set>

#include "common/printable_text.h"
#include "gst_scoped.h"
#include "http/camera_feed.h"
#include "http/http_responses.h"
#include "http/http_server.h"
#include "record/recording_query.h"
#include "record/telemetry_log.h"

namespace wircam::recorder {

namespace fs = std::filesystem;

namespace {

// Whether the request's Range (valid, "bytes=...") starts wholly past a file
// of `size` bytes. libsoup answers such a range 416 by itself, but without
// the Content-Range that says the size (RFC 9110 15.5.17).
bool rangePastTheEnd(SoupMessageHeaders* request, goffset size) {
  SoupRange* ranges = nullptr;
  int count = 0;
  if (size <= 0 || !soup_message_headers_get_ranges(request, size, &ranges, &count)) return false;
  bool past =
      std::all_of(ranges, ranges + count, [&](const SoupRange& r) { return r.start >= size; });
  soup_message_headers_free_ranges(request, ranges);
  return past;
}

}  // namespace

void HttpServer::serveSnapshot(SoupServerMessage* message, const std::string& camera) {
  auto feed =
      std::find_if(feeds_.begin(), feeds_.end(), [&](const auto& f) { return f->name == camera; });
  if (feed == feeds_.end())
    return respondJsonError(message, SOUP_STATUS_NOT_FOUND, "no camera named '" + camera + "'");
  GstBuffer* jpeg = nullptr;
  {
    std::lock_guard lock((*feed)->latestMutex);
    gst_buffer_replace(&jpeg, (*feed)->latest);
  }
  if (!jpeg)
    return respondJsonError(message, SOUP_STATUS_SERVICE_UNAVAILABLE,
                            "camera '" + camera + "' has sent no frame yet");
  // The frame untouched: the camera's own JPEG bytes.
  if (gst::ScopedBufferMap map(jpeg, GST_MAP_READ); map) {
    respond(message, SOUP_STATUS_OK, "image/jpeg", std::string(map.view()));
    soup_message_headers_replace(soup_server_message_get_response_headers(message), "Cache-Control",
                                 "no-cache, no-store");
  }
  gst_buffer_unref(jpeg);
}

void HttpServer::deleteRecording(SoupServerMessage* message, const std::string& name) {
  if (refusedWithoutToken(message, "deleting recordings")) return;
  if (!isRecordingName(name) || name.ends_with(".jsonl"))
    return respondJsonError(message, SOUP_STATUS_NOT_FOUND, "no recording named '" + name + "'");
  auto refused = content_.deleteRecording(name);
  if (!refused) {
    respond(message, SOUP_STATUS_OK, "application/json", nlohmann::json{{"deleted", name}}.dump());
    return;
  }
  respondJsonError(message, refused->first, refused->second);
}

void HttpServer::serveRecordingIndex(SoupServerMessage* message, GHashTable* query) {
  auto asked = recordingQueryOf(queryValue(query, "camera"), queryValue(query, "vehicle"),
                                queryValue(query, "day"));
  if (!asked) return respondJsonError(message, SOUP_STATUS_BAD_REQUEST, asked.error());
  nlohmann::json list = nlohmann::json::array();
  for (auto& entry : content_.recordings())
    if (matches(*asked, entry)) list.push_back(std::move(entry));
  for (auto& entry : list) {
    gchar* escaped = g_uri_escape_string(entry["file"].get<std::string>().c_str(), nullptr, FALSE);
    entry["url"] = std::string("/recordings/") + escaped;
    g_free(escaped);
  }
  respond(message, SOUP_STATUS_OK, "application/json", list.dump());
}

void HttpServer::serveRecordings(SoupServerMessage* message, const std::string& name) {
  fs::path folder = content_.recordingsFolder;
  if (name.empty()) {
    auto open = content_.openSegments();
    std::set<std::string> openNames;
    for (const auto& path : open) {
      openNames.insert(fs::path(path).filename().string());
      openNames.insert(fs::path(TelemetryLog::pathFor(path)).filename().string());
    }
    nlohmann::json files = nlohmann::json::array();
    std::error_code error;
    for (const auto& entry : fs::directory_iterator(folder, error)) {
      // A symbolic link could lead anywhere on the machine: never listed.
      if (entry.is_symlink(error) || !entry.is_regular_file(error) ||
          !isRecordingName(entry.path().filename().string()))
        continue;
      auto file = entry.path().filename().string();
      files.push_back({{"name", file},
                       {"bytes", entry.file_size(error)},
                       {"recording", openNames.count(file) > 0}});
    }
    std::sort(files.begin(), files.end(),
              [](const auto& a, const auto& b) { return a["name"] < b["name"]; });
    respond(message, SOUP_STATUS_OK, "application/json", files.dump());
    return;
  }
  // Only plain names of recordings in the folder, never a symbolic link:
  // no way out of it.
  fs::path file = folder / name;
  std::error_code error;
  if (!isRecordingName(name) || fs::is_symlink(fs::symlink_status(file, error)) ||
      !fs::is_regular_file(file, error)) {
    respondJsonError(
        message, SOUP_STATUS_NOT_FOUND,
        "no recording named '" + printableText(name) + "'; GET /api/recordings lists them");
    return;
  }
  auto size = static_cast<goffset>(fs::file_size(file, error));
  if (!error && std::string(soup_server_message_get_method(message)) == "GET" &&
      rangePastTheEnd(soup_server_message_get_request_headers(message), size)) {
    soup_message_headers_replace(soup_server_message_get_response_headers(message), "Content-Range",
                                 ("bytes */" + std::to_string(size)).c_str());
    return respondJsonError(
        message, SOUP_STATUS_REQUESTED_RANGE_NOT_SATISFIABLE,
        "the range starts past the end of the file (" + std::to_string(size) + " bytes)");
  }
  GError* mapError = nullptr;
  GMappedFile* mapped = g_mapped_file_new(file.c_str(), FALSE, &mapError);
  if (!mapped) {
    respondJsonError(message, SOUP_STATUS_INTERNAL_SERVER_ERROR, mapError->message);
    g_error_free(mapError);
    return;
  }
  GBytes* bytes = g_mapped_file_get_bytes(mapped);
  g_mapped_file_unref(mapped);
  soup_server_message_set_status(message, SOUP_STATUS_OK, nullptr);
  SoupMessageHeaders* headers = soup_server_message_get_response_headers(message);
  soup_message_headers_set_content_type(headers, recordingContentType(name), nullptr);
  // libsoup answers a Range request from the whole body: a <video> seeks.
  soup_message_headers_replace(headers, "Accept-Ranges", "bytes");
  soup_message_body_append_bytes(soup_server_message_get_response_body(message), bytes);
  g_bytes_unref(bytes);
}

}  // namespace wircam::recorder
