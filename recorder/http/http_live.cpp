// HttpServer's streams: live MJPEG to each viewer of a camera, a recording
// played back as MJPEG, server-sent events (detections) to the page. A client that falls behind is skipped until it
// catches up, never waited for.
#include <algorithm>
#include <cmath>
#include <filesystem>

#include "gst_scoped.h"
#include "http/camera_feed.h"
#include "http/http_responses.h"
#include "http/http_server.h"
#include "recording/playback_stream.h"

namespace wircam::recorder {

namespace fs = std::filesystem;

namespace {

constexpr char kBoundary[] = "wircframe";
// A client this many frames behind is skipped until it catches up, so a
// slow viewer never makes the recorder hold frames for it.
constexpr int kMaxFramesInFlight = 3;

// One part of a multipart/x-mixed-replace stream, built in one piece: a
// single copy of the frame per delivery. `extraHeaders` end in CRLF.
GBytes* multipartFrame(GstBuffer* jpeg, const std::string& extraHeaders) {
  gst::ScopedBufferMap map(jpeg, GST_MAP_READ);
  if (!map) return nullptr;
  std::string header =
      std::string("--") + kBoundary +
      "\r\nContent-Type: image/jpeg\r\nContent-Length: " + std::to_string(map.size()) + "\r\n" +
      extraHeaders + "\r\n";
  GByteArray* part = g_byte_array_sized_new(static_cast<guint>(header.size() + map.size() + 2));
  g_byte_array_append(part, reinterpret_cast<const guint8*>(header.data()),
                      static_cast<guint>(header.size()));
  g_byte_array_append(part, map.data(), static_cast<guint>(map.size()));
  g_byte_array_append(part, reinterpret_cast<const guint8*>("\r\n"), 2);
  return g_byte_array_free_to_bytes(part);
}

}  // namespace

void HttpServer::openStream(SoupServerMessage* message, const char* contentType,
                            std::vector<std::unique_ptr<Client>>& clients) {
  soup_server_message_set_status(message, SOUP_STATUS_OK, nullptr);
  SoupMessageHeaders* headers = soup_server_message_get_response_headers(message);
  soup_message_headers_set_encoding(headers, SOUP_ENCODING_CHUNKED);
  soup_message_headers_set_content_type(headers, contentType, nullptr);
  soup_message_headers_replace(headers, "Cache-Control", "no-cache, no-store");
  // Written chunks are freed, not kept for the whole life of the response.
  soup_message_body_set_accumulate(soup_server_message_get_response_body(message), FALSE);

  auto client = std::make_unique<Client>();
  client->message = message;
  Client* raw = client.get();
  // libsoup 3's wrote-chunk carries no argument: the handler is (message,
  // data). A chunk-size parameter here would read the client from a stray
  // register.
  client->wroteHandler = g_signal_connect(
      message, "wrote-chunk",
      G_CALLBACK(+[](SoupServerMessage*, gpointer c) { --static_cast<Client*>(c)->inFlight; }),
      raw);
  struct Finished {
    std::vector<std::unique_ptr<Client>>* clients;
    Client* client;
  };
  client->finishedHandler = g_signal_connect_data(
      message, "finished", G_CALLBACK(+[](SoupServerMessage*, gpointer data) {
        // The viewer went away: forget it.
        auto* f = static_cast<Finished*>(data);
        auto& list = *f->clients;
        auto it = std::find_if(list.begin(), list.end(),
                               [&](const auto& c) { return c.get() == f->client; });
        if (it != list.end()) {
          g_signal_handler_disconnect(f->client->message, f->client->wroteHandler);
          list.erase(it);  // the finished handler itself stays until the message dies
        }
      }),
      new Finished{&clients, raw},
      [](gpointer data, GClosure*) { delete static_cast<Finished*>(data); }, GConnectFlags(0));
  clients.push_back(std::move(client));
  soup_server_message_pause(message);
}

void HttpServer::send(std::vector<std::unique_ptr<Client>>& clients, GBytes* chunk) {
  for (auto& client : clients) sendTo(*client, chunk);
}

void HttpServer::sendTo(Client& client, GBytes* chunk) {
  if (client.inFlight >= kMaxFramesInFlight) return;
  ++client.inFlight;
  soup_message_body_append_bytes(soup_server_message_get_response_body(client.message), chunk);
  soup_server_message_unpause(client.message);
}

void HttpServer::serveLive(SoupServerMessage* message, const std::string& camera) {
  auto feed =
      std::find_if(feeds_.begin(), feeds_.end(), [&](const auto& f) { return f->name == camera; });
  if (feed == feeds_.end()) {
    respondError(message, SOUP_STATUS_NOT_FOUND, "no camera named '" + camera + "'");
    return;
  }
  std::string type = std::string("multipart/x-mixed-replace; boundary=") + kBoundary;
  openStream(message, type.c_str(), (*feed)->clients);
  (*feed)->clientCount = static_cast<int>((*feed)->clients.size());
  // The status and headers now, whether or not the camera has a frame yet:
  // a client waiting on a silent socket cannot tell a slow camera from a
  // dead server. libsoup pauses again when it runs out of parts.
  soup_server_message_unpause(message);
}

void HttpServer::sendFrame(const std::string& camera, GstBuffer* jpeg) {
  auto found =
      std::find_if(feeds_.begin(), feeds_.end(), [&](const auto& f) { return f->name == camera; });
  if (found == feeds_.end()) return;  // removed by a reload meanwhile
  auto& feed = **found;
  feed.clientCount = static_cast<int>(feed.clients.size());
  if (feed.clients.empty()) return;
  GBytes* chunk = multipartFrame(jpeg, "");
  if (!chunk) return;
  send(feed.clients, chunk);
  g_bytes_unref(chunk);
}

void HttpServer::serveEvents(SoupServerMessage* message) {
  openStream(message, "text/event-stream", eventClients_);
  GBytes* hello = g_bytes_new_static("retry: 2000\n\n", 13);
  send(eventClients_, hello);
  g_bytes_unref(hello);
}

void HttpServer::publishDetections(const std::string& camera, const nlohmann::json& detections) {
  for (auto& feed : feeds_)
    if (feed->name == camera) feed->detections = detections;
  if (eventClients_.empty()) return;
  nlohmann::json event = {{"stream", camera}, {"detections", detections}};
  std::string text = "event: detections\ndata: " + event.dump() + "\n\n";
  GBytes* chunk = g_bytes_new(text.data(), text.size());
  send(eventClients_, chunk);
  g_bytes_unref(chunk);
}

void HttpServer::servePlayback(SoupServerMessage* message, const std::string& name,
                               GHashTable* query) {
  fs::path file = fs::path(content_.recordingsFolder) / name;
  std::error_code error;
  if (!isRecordingName(name) || !name.ends_with(".mkv") ||
      fs::is_symlink(fs::symlink_status(file, error)) || !fs::is_regular_file(file, error))
    return respondJsonError(
        message, SOUP_STATUS_NOT_FOUND,
        "no Matroska recording named '" + name + "' (MP4 recordings play from /recordings/FILE)");
  double from = 0;
  if (const char* text = queryValue(query, "from")) {
    char* end = nullptr;
    from = g_ascii_strtod(text, &end);
    if (end == text || *end != '\0' || !std::isfinite(from) || from < 0)
      return respondJsonError(
          message, SOUP_STATUS_BAD_REQUEST,
          "from= takes seconds into the recording, not '" + std::string(text).substr(0, 40) + "'");
  }
  if (playbackClients_.size() >= kMaxPlaybacks)
    return respondJsonError(
        message, SOUP_STATUS_SERVICE_UNAVAILABLE,
        "already replaying " + std::to_string(kMaxPlaybacks) + " recordings; try again later");
  PlaybackStream::Callbacks callbacks;
  callbacks.frame = [this, message](GstBuffer* jpeg, double position) {
    char header[48];
    g_snprintf(header, sizeof header, "X-Position: %.3f\r\n", position);
    GBytes* chunk = multipartFrame(jpeg, header);
    if (!chunk) return;
    for (auto& client : playbackClients_)
      if (client->message == message) sendTo(*client, chunk);
    g_bytes_unref(chunk);
  };
  callbacks.ended = [message](const std::string&) {
    // The end of the response: the viewer's stream closes, its replay goes.
    soup_message_body_complete(soup_server_message_get_response_body(message));
    soup_server_message_unpause(message);
  };
  auto playback = PlaybackStream::start(file.string(), from, std::move(callbacks));
  if (!playback)
    return respondJsonError(
        message,
        playback.error().pastTheEnd ? SOUP_STATUS_BAD_REQUEST : SOUP_STATUS_UNSUPPORTED_MEDIA_TYPE,
        playback.error().text);
  std::string type = std::string("multipart/x-mixed-replace; boundary=") + kBoundary;
  openStream(message, type.c_str(), playbackClients_);
  playbackClients_.back()->playback = std::move(*playback);
}

}  // namespace wircam::recorder
