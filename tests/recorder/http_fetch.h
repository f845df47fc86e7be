// One HTTP request from the recorder tests, through a real client (libsoup).
#pragma once

#include <glib.h>

#include <string>

namespace wircam::testing {

struct Response {
  guint status = 0;
  std::string contentType;
  std::string body;
};

Response fetch(const std::string& url, const char* method = "GET");

}  // namespace wircam::testing
