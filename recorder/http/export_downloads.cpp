#include "http/export_downloads.h"

#include <sys/socket.h>

#include <algorithm>
#include <atomic>
#include <fstream>
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

// "2026-11-24T14:59:35.467Z" → "20261124T145935Z", for a file name.
std::string compactTime(int64_t unixNs) {
  std::string compact;
  for (char c : isoTimeOf(unixNs)) {
    if (c == '.') return compact + "Z";
    if (c != '-' && c != ':') compact += c;
  }
  return compact;
}

// The name a browser saves the file as: the camera and the range.
std::string downloadName(const std::string& camera, const ExportReport& report,
                         ExportFormat format) {
  std::string name;
  for (char c : camera) name += g_ascii_isalnum(c) || c == '-' || c == '.' ? c : '_';
  return name + "_" + compactTime(report.firstUtcNs) + "-" + compactTime(report.lastUtcNs) + "." +
         exportFormatName(format);
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
  SoupServerMessage* message = nullptr;
  gulong finishedHandler = 0, wroteHandler = 0;
  ExportRequest request;
  std::atomic<bool> stop{false};
  std::optional<Expected<ExportReport, ExportError>> result;  // the worker's, read after it posts
  std::thread worker;
  GSocket* socket = nullptr;  // the client's, borrowed: looked at while exporting
  guint clientCheck = 0;
  std::ifstream file;
  bool sentAll = false;
  // The result on its way to the main loop checks it: the download may be gone.
  std::shared_ptr<bool> alive = std::make_shared<bool>(true);

  // The file's next block, or the body's end after its last.
  void sendNextBlock() {
    // Read into memory the body then owns: no copy, freed once written.
    auto* block = static_cast<char*>(g_malloc(kBlockBytes));
    file.read(block, static_cast<std::streamsize>(kBlockBytes));
    auto* body = soup_server_message_get_response_body(message);
    if (file.gcount() > 0) {
      soup_message_body_append(body, SOUP_MEMORY_TAKE, block, static_cast<gsize>(file.gcount()));
    } else {
      g_free(block);
      soup_message_body_complete(body);
      sentAll = true;
    }
    soup_server_message_unpause(message);
  }

  // The export's files, written or half written: never kept.
  void removeFiles() {
    file.close();
    std::error_code ignored;
    fs::remove(request.out, ignored);
    fs::remove(fs::path(request.out).replace_extension(".jsonl"), ignored);
  }

  // The response is over: the export stopped (if it still ran), its files
  // gone, and then the recorder's log says how it ended (a reader of the log
  // finds nothing left behind).
  void end() {
    stop = true;
    if (worker.joinable()) worker.join();  // the result is written then
    removeFiles();
    std::string what =
        "export of " + request.camera + " (" + exportFormatName(request.format) + ")";
    if (!result) return;
    if (!*result) {
      bool stopped = result->error().kind == ExportError::Kind::kCancelled;
      logLine(what + (stopped ? ": stopped, the client left" : ": " + result->error().message));
    } else {
      logLine(what + (sentAll ? ": " + std::to_string((*result)->frames) + " frames sent"
                              : ": the client left before the end"));
    }
  }

  ~Download() {
    if (clientCheck) g_source_remove(clientCheck);
    stop = true;
    if (worker.joinable()) worker.join();
    if (message) {
      // The server is going away with the response unfinished.
      g_signal_handler_disconnect(message, finishedHandler);
      if (wroteHandler) g_signal_handler_disconnect(message, wroteHandler);
    }
    removeFiles();
  }
};

ExportDownloads::ExportDownloads(fs::path recordings, SocketOf socketOf)
    : recordings_(std::move(recordings)),
      scratch_(recordings_ / ".exports"),
      socketOf_(std::move(socketOf)) {
  std::error_code ignored;
  fs::remove_all(scratch_, ignored);
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
  std::error_code error;
  fs::create_directories(scratch_, error);
  range.out = scratch_ / (std::to_string(++serial_) + "." + exportFormatName(*format));

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
  // requests) would answer it; the real one is set when the export is done.
  soup_server_message_set_status(message, SOUP_STATUS_OK, nullptr);
  soup_server_message_pause(message);
  download->socket = socketOf_ ? socketOf_(message) : nullptr;
  if (download->socket) download->clientCheck = g_timeout_add(500, checkClient, download);
  download->worker = std::thread([this, download, alive = std::weak_ptr<bool>(download->alive)] {
    download->result = exportRange(
        download->request, [download](uint64_t, uint64_t) { return !download->stop.load(); });
    struct Done {
      ExportDownloads* self;
      Download* download;
      std::weak_ptr<bool> alive;
    };
    g_main_context_invoke_full(
        nullptr, G_PRIORITY_DEFAULT,
        [](gpointer data) -> gboolean {
          auto* done = static_cast<Done*>(data);
          if (!done->alive.expired()) done->self->exported(done->download);
          return G_SOURCE_REMOVE;
        },
        new Done{this, download, alive}, [](gpointer data) { delete static_cast<Done*>(data); });
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

void ExportDownloads::exported(Download* download) {
  if (download->clientCheck) g_source_remove(std::exchange(download->clientCheck, 0));
  download->worker.join();
  SoupServerMessage* message = download->message;
  auto& result = *download->result;
  if (!result) {
    guint status = SOUP_STATUS_INTERNAL_SERVER_ERROR;
    if (result.error().kind == ExportError::Kind::kNothing) status = SOUP_STATUS_NOT_FOUND;
    if (result.error().kind == ExportError::Kind::kUnsupported)
      status = SOUP_STATUS_UNSUPPORTED_MEDIA_TYPE;
    respondJsonError(message, status, result.error().message);
    soup_server_message_unpause(message);
    return;
  }
  std::error_code error;
  auto bytes = fs::file_size(download->request.out, error);
  download->file.open(download->request.out, std::ios::binary);
  if (error || !download->file) {
    respondJsonError(message, SOUP_STATUS_INTERNAL_SERVER_ERROR,
                     "the export was written but cannot be read back");
    soup_server_message_unpause(message);
    return;
  }
  soup_server_message_set_status(message, SOUP_STATUS_OK, nullptr);
  SoupMessageHeaders* headers = soup_server_message_get_response_headers(message);
  soup_message_headers_set_content_type(headers, contentTypeOf(download->request.format), nullptr);
  soup_message_headers_set_content_length(headers, static_cast<goffset>(bytes));
  std::string name = downloadName(download->request.camera, *result, download->request.format);
  soup_message_headers_replace(headers, "Content-Disposition",
                               ("attachment; filename=\"" + name + "\"").c_str());
  soup_message_headers_replace(headers, "X-Export-Frames", std::to_string(result->frames).c_str());
  // What was left out and why (a segment still being written, a broken one),
  // as ASCII JSON: a header carries no other bytes safely.
  soup_message_headers_replace(headers, "X-Export-Notes",
                               nlohmann::json(result->notes)
                                   .dump(-1, ' ', true, nlohmann::json::error_handler_t::replace)
                                   .c_str());
  soup_message_headers_replace(headers, "Cache-Control", "no-store");
  // Blocks sent are freed, not kept for the whole response.
  soup_message_body_set_accumulate(soup_server_message_get_response_body(message), FALSE);
  download->wroteHandler =
      g_signal_connect(message, "wrote-chunk", G_CALLBACK(+[](SoupServerMessage*, gpointer d) {
                         static_cast<Download*>(d)->sendNextBlock();
                       }),
                       download);
  download->sendNextBlock();
}

void ExportDownloads::forget(Download* download) {
  std::erase_if(downloads_, [&](const auto& d) { return d.get() == download; });
}

}  // namespace wircam::recorder
