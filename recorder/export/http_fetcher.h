// A blocking HTTP(S) client for wirc-export --fleet (libsoup; the system's
// CAs for HTTPS), with the fleet's bearer token on every request: small
// JSON answers, and files fetched whole, a connection that drops taken up
// again where it broke (a range request).
#pragma once

#include <libsoup/soup.h>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "common/expected.h"

namespace wircam::recorder {

class HttpFetcher {
 public:
  // Times a request out after `timeout` without a byte.
  explicit HttpFetcher(std::string token, std::chrono::seconds timeout = std::chrono::seconds(15));
  ~HttpFetcher();
  HttpFetcher(const HttpFetcher&) = delete;
  HttpFetcher& operator=(const HttpFetcher&) = delete;

  // A 200 answer's JSON, or why not (no answer, a 401 said as such).
  Expected<nlohmann::json, std::string> json(const std::string& url);

  // `url` into `file` (replaced). A connection that breaks is taken up
  // again from the bytes already there, up to five times, a little later
  // each; a server that ignores the range starts the file over. nullopt
  // when whole; with `missingOk`, a 404 is not an error (and leaves no file).
  std::optional<std::string> download(const std::string& url, const std::filesystem::path& file,
                                      bool missingOk = false);
  // Connections taken up again so far (what the last downloads needed).
  int resumed() const { return resumed_; }

 private:
  SoupMessage* request(const std::string& url) const;

  std::string token_;
  SoupSession* session_ = nullptr;
  int resumed_ = 0;
};

}  // namespace wircam::recorder
