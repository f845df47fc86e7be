// One HTTP request from the recorder tests, through a real client (libsoup).
#pragma once

#include <glib.h>

#include <map>
#include <string>
#include <utility>
#include <vector>

namespace wircam::testing {

struct Response {
  guint status = 0;
  std::string contentType;
  std::string body;
  std::string authenticate;                    // the WWW-Authenticate headers, joined by ", "
  std::map<std::string, std::string> headers;  // every response header, by its name in lower case
};

using Headers = std::vector<std::pair<std::string, std::string>>;

// `body`, if any, goes with the Content-Type header given in `headers`.
Response fetch(const std::string& url, const char* method = "GET", const Headers& headers = {},
               const std::string& body = "");

}  // namespace wircam::testing
