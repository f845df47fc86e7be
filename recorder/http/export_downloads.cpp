#include "http/export_downloads.h"

#include <glib-unix.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <mutex>
#include <optional>
#include <thread>
#include <utility>

#include "common/printable_text.h"
#include "export/exporter.h"
#include "http/http_responses.h"
#include "log_line.h"
#include "recording/segment_selection.h"

namespace wircam::recorder {

namespace fs = std::filesystem;

namespace {

// Small enough to keep a slow client's download from holding memory, large
// enough that the main loop is not woken per packet.
constexpr size_t kBlockBytes = 256 * 1024;

const char* contentTypeOf(ExportFormat format) {
  switch (format) {
    case ExportFormat::kMkv:
      return "video/x-matroska";
    case ExportFormat::kMp4:
      return "video/mp4";
    case ExportFormat::kMcap:
      return "application/octet-stream";  // MCAP has no registered media type
  }
  return "application/octet-stream";
}

// The name a browser saves the file as: the camera and the range (its
// first frame to its planned end).
std::string downloadName(const std::string& camera, const ExportStart& start, ExportFormat format) {
  return fileNamePart(camera) + "_" + compactTimeOf(start.firstUtcNs) + "-" +
         compactTimeOf(start.lastUtcNs) + "." + exportFormatName(format);
}

// A form-decoded query turns the '+' of "+01:00" into a space; no ISO 8601
// time holds a space, so it is given back.
std::optional<int64_t> queryTime(const char* text) {
  std::string time = text;
  std::replace(time.begin(), time.end(), ' ', '+');
  return parseIsoTime(time);
}

}  // namespace

struct ExportDownloads::Download {
  ExportDownloads* owner = nullptr;
  SoupServerMessage* message = nullptr;  // null once libsoup is done with it
  gulong finishedHandler = 0, wroteHandler = 0;
  ExportRequest request;  // its `stream` is the worker's end, closed by the worker
  int readEnd = -1;       // ours, non-blocking
  guint readable = 0;     // the watch on readEnd, while a block is wanted
  std::atomic<bool> stop{false};
  std::thread worker;
  GSocket* socket = nullptr;  // the client's, borrowed: looked at until the first bytes
  guint clientCheck = 0;
  std::mutex startLock;
  std::optional<ExportStart> start;  // the worker's, set before its first byte
  std::optional<Expected<ExportReport, ExportError>> result;  // the worker's
  bool exported = false;  // the worker joined: `result` is ours to read
  bool atEnd = false;     // the worker's end closed and everything read
  bool responding = false, sentAll = false;
  // The result on its way to the main loop checks it: the download may be gone.
  std::shared_ptr<bool> alive = std::make_shared<bool>(true);

  void watch() {
    readable = g_unix_fd_add(readEnd, static_cast<GIOCondition>(G_IO_IN | G_IO_HUP | G_IO_ERR),
                             onReadable, this);
  }

  // A block of the file, then nothing until libsoup has written it.
  static gboolean onReadable(int fd, GIOCondition, gpointer data) {
    auto* self = static_cast<Download*>(data);
    // Read into memory the body then owns: no copy, freed once written.
    auto* block = static_cast<char*>(g_malloc(kBlockBytes));
    ssize_t got = read(fd, block, kBlockBytes);
    if (got < 0 && (errno == EAGAIN || errno == EINTR)) {
      g_free(block);
      return G_SOURCE_CONTINUE;
    }
    self->readable = 0;
    if (got <= 0) {
      g_free(block);
      self->atEnd = true;
      self->finish();
      return G_SOURCE_REMOVE;
    }
    if (!self->responding) self->beginResponse();
    soup_message_body_append(soup_server_message_get_response_body(self->message), SOUP_MEMORY_TAKE,
                             block, static_cast<gsize>(got));
    soup_server_message_unpause(self->message);
    return G_SOURCE_REMOVE;
  }

  // The headers, with the first bytes: what is known as the first frame went in.
  void beginResponse() {
    responding = true;
    // From here libsoup, writing, sees a client that left.
    if (clientCheck) g_source_remove(std::exchange(clientCheck, 0));
    ExportStart started;
    {
      std::lock_guard lock(startLock);
      if (start) started = *start;
    }
    soup_server_message_set_status(message, SOUP_STATUS_OK, nullptr);
    SoupMessageHeaders* headers = soup_server_message_get_response_headers(message);
    soup_message_headers_set_encoding(headers, SOUP_ENCODING_CHUNKED);
    soup_message_headers_set_content_type(headers, contentTypeOf(request.format), nullptr);
    std::string name = downloadName(request.camera, started, request.format);
    soup_message_headers_replace(headers, "Content-Disposition",
                                 ("attachment; filename=\"" + name + "\"").c_str());
    // What was left out before the first frame and why (a segment still
    // being written, a broken one), as ASCII JSON: a header carries no
    // other bytes safely. What the export meets later goes to the log.
    soup_message_headers_replace(headers, "X-Export-Notes",
                                 nlohmann::json(started.notes)
                                     .dump(-1, ' ', true, nlohmann::json::error_handler_t::replace)
                                     .c_str());
    soup_message_headers_replace(headers, "Cache-Control", "no-store");
    // Blocks sent are freed, not kept for the whole response.
    soup_message_body_set_accumulate(soup_server_message_get_response_body(message), FALSE);
    wroteHandler =
        g_signal_connect(message, "wrote-chunk", G_CALLBACK(+[](SoupServerMessage*, gpointer d) {
                           auto* self = static_cast<Download*>(d);
                           if (!self->atEnd && !self->readable) self->watch();
                         }),
                         this);
  }

  // Once the worker is joined and its stream read to the end: the response
  // ends as the export did.
  void finish() {
    if (!exported || !atEnd || !message) return;
    if (!responding) {  // not a byte made: said in JSON
      guint status = SOUP_STATUS_INTERNAL_SERVER_ERROR;
      std::string reason = "the export made nothing";
      if (!*result) {
        auto kind = result->error().kind;
        if (kind == ExportError::Kind::kNothing) status = SOUP_STATUS_NOT_FOUND;
        if (kind == ExportError::Kind::kUnsupported) status = SOUP_STATUS_UNSUPPORTED_MEDIA_TYPE;
        reason = result->error().message;
      }
      respondJsonError(message, status, reason);
    } else if (*result) {
      soup_message_body_complete(soup_server_message_get_response_body(message));
      sentAll = true;
    } else {
      // Broken off: the response must not end as if whole (its last chunk
      // would say so), so its connection goes.
      GSocket* connection = socket ? socket : soup_server_message_get_socket(message);
      if (connection) shutdown(g_socket_get_fd(connection), SHUT_RDWR);
    }
    soup_server_message_unpause(message);
  }

  void closeReadEnd() {
    if (readable) g_source_remove(std::exchange(readable, 0));
    if (readEnd >= 0) close(std::exchange(readEnd, -1));
  }

  // The response is over: the export stopped (if it still ran; our end
  // closed, its writes fail), and then the recorder's log says how it ended.
  void end() {
    stop = true;
    closeReadEnd();
    if (worker.joinable()) worker.join();  // the result is written then
    std::string what =
        "export of " + request.camera + " (" + exportFormatName(request.format) + ")";
    if (!result) return;
    if (sentAll) {
      logLine(what + ": " + std::to_string((*result)->frames) + " frames sent");
    } else if (responding || (!*result && result->error().kind == ExportError::Kind::kCancelled)) {
      logLine(what + ": stopped, the client left");
    } else if (!*result) {
      logLine(what + ": " + result->error().message);
    }
  }

  ~Download() {
    if (clientCheck) g_source_remove(clientCheck);
    stop = true;
    closeReadEnd();
    if (worker.joinable()) worker.join();
    if (message) {
      // The server is going away with the response unfinished.
      g_signal_handler_disconnect(message, finishedHandler);
      if (wroteHandler) g_signal_handler_disconnect(message, wroteHandler);
    }
  }
};

ExportDownloads::ExportDownloads(fs::path recordings, SocketOf socketOf)
    : recordings_(std::move(recordings)), socketOf_(std::move(socketOf)) {
  // Where exports were written before they were streamed.
  std::error_code ignored;
  if (!recordings_.empty()) fs::remove_all(recordings_ / ".exports", ignored);
}

ExportDownloads::~ExportDownloads() { downloads_.clear(); }

void ExportDownloads::serve(SoupServerMessage* message, GHashTable* query) {
  constexpr const char* kForm =
      "; GET /api/export?camera=NAME&start=ISO8601&end=ISO8601&format=mkv|mp4|mcap";
  const char* camera = queryValue(query, "camera");
  if (!camera || !*camera)
    return respondJsonError(message, SOUP_STATUS_BAD_REQUEST,
                            std::string("camera= is needed") + kForm);
  const char* formatName = queryValue(query, "format");
  auto format = formatName ? exportFormatOf(formatName) : std::nullopt;
  if (!format)
    return respondJsonError(message, SOUP_STATUS_BAD_REQUEST,
                            std::string("format= is mkv, mp4 or mcap") + kForm);
  auto owned = std::make_unique<Download>();
  Download* download = owned.get();
  auto& range = download->request;
  range.recordings = recordings_;
  range.camera = camera;
  range.format = *format;
  for (auto [key, bound] : {std::pair{"start", &range.start}, std::pair{"end", &range.end}}) {
    const char* text = queryValue(query, key);
    if (!text) continue;
    *bound = queryTime(text);
    if (!*bound)
      return respondJsonError(message, SOUP_STATUS_BAD_REQUEST,
                              std::string(key) + "= '" +
                                  printableText(std::string(text).substr(0, 40)) +
                                  "' is not an ISO 8601 time like 2026-11-24T14:59:35Z");
  }
  if (range.start && range.end && *range.end < *range.start)
    return respondJsonError(message, SOUP_STATUS_BAD_REQUEST, "end= is before start=");
  if (recordings_.empty())
    return respondJsonError(message, SOUP_STATUS_NOT_FOUND, "this recorder records nothing");
  if (downloads_.size() >= kMaxAtOnce)
    return respondJsonError(
        message, SOUP_STATUS_SERVICE_UNAVAILABLE,
        "already exporting " + std::to_string(kMaxAtOnce) + " ranges; try again when one is done");
  int ends[2];
  if (socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, ends) != 0)
    return respondJsonError(message, SOUP_STATUS_SERVICE_UNAVAILABLE,
                            std::string("cannot start an export: ") + std::strerror(errno));
  download->readEnd = ends[0];
  g_unix_set_fd_nonblocking(ends[0], TRUE, nullptr);
  range.stream = ends[1];
  range.out = range.camera + "." + exportFormatName(*format);  // for messages only

  download->message = message;
  download->owner = this;
  download->finishedHandler =
      g_signal_connect(message, "finished", G_CALLBACK(+[](SoupServerMessage*, gpointer data) {
                         auto* d = static_cast<Download*>(data);
                         d->message = nullptr;  // libsoup is done with it
                         d->end();
                         d->owner->forget(d);
                       }),
                       download);
  // A status now, or the WebSocket handler (which upgrades only unanswered
  // requests) would answer it; the real one is set with the first bytes.
  soup_server_message_set_status(message, SOUP_STATUS_OK, nullptr);
  soup_server_message_pause(message);
  download->socket = socketOf_ ? socketOf_(message) : nullptr;
  if (download->socket) download->clientCheck = g_timeout_add(500, checkClient, download);
  download->watch();
  download->worker = std::thread([download, alive = std::weak_ptr<bool>(download->alive)] {
    auto result = exportRange(
        download->request,
        [download](uint64_t, uint64_t, uint64_t) { return !download->stop.load(); },
        [download](const ExportStart& start) {
          std::lock_guard lock(download->startLock);
          download->start = start;
        });
    download->result = std::move(result);
    close(download->request.stream);  // the end of the file, for the reader
    struct Done {
      Download* download;
      std::weak_ptr<bool> alive;
    };
    g_main_context_invoke_full(
        nullptr, G_PRIORITY_DEFAULT,
        [](gpointer data) -> gboolean {
          auto* done = static_cast<Done*>(data);
          if (done->alive.expired()) return G_SOURCE_REMOVE;
          Download* finished = done->download;
          finished->worker.join();
          finished->exported = true;
          finished->finish();
          return G_SOURCE_REMOVE;
        },
        new Done{download, alive}, [](gpointer data) { delete static_cast<Done*>(data); });
  });
  downloads_.push_back(std::move(owned));
}

gboolean ExportDownloads::checkClient(gpointer data) {
  auto* download = static_cast<Download*>(data);
  // Readable with nothing to read: the client closed its end. (Bytes there
  // are a next request, sent ahead: the client is still there.)
  GIOCondition ready = g_socket_condition_check(
      download->socket, static_cast<GIOCondition>(G_IO_IN | G_IO_HUP | G_IO_ERR));
  char byte;
  bool gone = (ready & (G_IO_HUP | G_IO_ERR)) ||
              ((ready & G_IO_IN) &&
               recv(g_socket_get_fd(download->socket), &byte, 1, MSG_PEEK | MSG_DONTWAIT) == 0);
  if (!gone) return G_SOURCE_CONTINUE;
  download->stop = true;
  download->clientCheck = 0;
  return G_SOURCE_REMOVE;
}

void ExportDownloads::forget(Download* download) {
  std::erase_if(downloads_, [&](const auto& d) { return d.get() == download; });
}

}  // namespace wircam::recorder
