#include "export/http_fetcher.h"

#include <unistd.h>

#include <cstdio>
#include <thread>
#include <vector>

namespace wircam::recorder {

namespace fs = std::filesystem;
using std::chrono::milliseconds;

namespace {

constexpr int kAttempts = 6;  // the first and five resumptions

// The body to its end into `out`, counting `have`; false (and why) when the
// connection broke first.
bool copyBody(GInputStream* stream, FILE* out, uint64_t& have, std::string& problem) {
  std::vector<char> block(256 * 1024);
  while (true) {
    GError* error = nullptr;
    gssize got = g_input_stream_read(stream, block.data(), block.size(), nullptr, &error);
    if (got == 0) return true;
    if (got < 0) {
      problem = error->message;
      g_error_free(error);
      return false;
    }
    if (std::fwrite(block.data(), 1, static_cast<size_t>(got), out) != static_cast<size_t>(got)) {
      problem = "cannot write it";
      return false;
    }
    have += static_cast<uint64_t>(got);
  }
}

}  // namespace

HttpFetcher::HttpFetcher(std::string token, std::chrono::seconds timeout)
    : token_(std::move(token)),
      session_(soup_session_new_with_options("timeout", static_cast<guint>(timeout.count()),
                                             "idle-timeout", static_cast<guint>(timeout.count()),
                                             nullptr)) {}

HttpFetcher::~HttpFetcher() { g_object_unref(session_); }

SoupMessage* HttpFetcher::request(const std::string& url) const {
  SoupMessage* message = soup_message_new("GET", url.c_str());
  if (message && !token_.empty())
    soup_message_headers_replace(soup_message_get_request_headers(message), "Authorization",
                                 ("Bearer " + token_).c_str());
  return message;
}

Expected<nlohmann::json, std::string> HttpFetcher::json(const std::string& url) {
  SoupMessage* message = request(url);
  if (!message) return unexpected("not a URL: " + url);
  GError* error = nullptr;
  GBytes* body = soup_session_send_and_read(session_, message, nullptr, &error);
  guint status = soup_message_get_status(message);
  g_object_unref(message);
  if (!body) {
    std::string why = error->message;
    g_error_free(error);
    return unexpected("no answer: " + why);
  }
  gsize size = 0;
  const auto* data = static_cast<const char*>(g_bytes_get_data(body, &size));
  auto parsed = nlohmann::json::parse(data, data + size, nullptr, false);
  g_bytes_unref(body);
  if (status == SOUP_STATUS_UNAUTHORIZED)
    return unexpected(std::string("answered 401 (its --http-token is not the one given)"));
  if (status != SOUP_STATUS_OK || parsed.is_discarded())
    return unexpected("answered " + std::to_string(status));
  return parsed;
}

std::optional<std::string> HttpFetcher::download(const std::string& url, const fs::path& file,
                                                 bool missingOk) {
  FILE* out = std::fopen(file.c_str(), "wb");
  if (!out) return "cannot write " + file.string();
  uint64_t have = 0;
  std::string problem;
  for (int attempt = 0; attempt < kAttempts; ++attempt) {
    if (attempt > 0) {
      ++resumed_;
      std::this_thread::sleep_for(milliseconds(200 * attempt));
    }
    SoupMessage* message = request(url);
    if (!message) {
      problem = "not a URL";
      break;
    }
    if (have > 0)
      soup_message_headers_replace(soup_message_get_request_headers(message), "Range",
                                   ("bytes=" + std::to_string(have) + "-").c_str());
    GError* error = nullptr;
    GInputStream* stream = soup_session_send(session_, message, nullptr, &error);
    guint status = soup_message_get_status(message);
    // What this answer owes: a body that ends short of it broke off (libsoup
    // reads a closed connection as the body's end).
    SoupMessageHeaders* headers = soup_message_get_response_headers(message);
    std::optional<uint64_t> owed;
    if (soup_message_headers_get_encoding(headers) == SOUP_ENCODING_CONTENT_LENGTH)
      owed = static_cast<uint64_t>(soup_message_headers_get_content_length(headers));
    g_object_unref(message);
    if (!stream) {
      problem = error->message;
      g_error_free(error);
      continue;
    }
    bool whole = false;
    if (status == SOUP_STATUS_NOT_FOUND && missingOk && have == 0) {
      g_object_unref(stream);
      std::fclose(out);
      fs::remove(file);
      return std::nullopt;
    }
    if (status == SOUP_STATUS_OK && have > 0) {  // the range not taken: from the start
      have = 0;
      std::fflush(out);
      if (ftruncate(fileno(out), 0) != 0 || std::fseek(out, 0, SEEK_SET) != 0) {
        problem = "cannot start " + file.string() + " over";
        attempt = kAttempts;
      }
    }
    if (attempt < kAttempts &&
        (status == SOUP_STATUS_OK || status == SOUP_STATUS_PARTIAL_CONTENT)) {
      uint64_t before = have;
      whole = copyBody(stream, out, have, problem);
      if (whole && owed && have - before < *owed) {
        whole = false;
        problem = "the connection broke after " + std::to_string(have) + " bytes";
      }
    } else if (attempt < kAttempts) {
      problem = "answered " + std::to_string(status);
      attempt = kAttempts;  // not a dropped connection: no use asking again
    }
    g_object_unref(stream);
    if (whole)
      return std::fclose(out) == 0 ? std::nullopt : std::optional("cannot write " + file.string());
  }
  std::fclose(out);
  fs::remove(file);
  return url + ": " + problem;
}

}  // namespace wircam::recorder
