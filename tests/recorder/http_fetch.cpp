#include "http_fetch.h"

#include <libsoup/soup.h>

namespace wircam::testing {

Response fetch(const std::string& url, const char* method, const Headers& headers,
               const std::string& body) {
  SoupSession* session = soup_session_new();
  SoupMessage* message = soup_message_new(method, url.c_str());
  std::string bodyType = "application/octet-stream";
  for (const auto& [name, value] : headers) {
    soup_message_headers_replace(soup_message_get_request_headers(message), name.c_str(),
                                 value.c_str());
    if (g_ascii_strcasecmp(name.c_str(), "Content-Type") == 0) bodyType = value;
  }
  if (!body.empty()) {
    GBytes* bytes = g_bytes_new(body.data(), body.size());
    soup_message_set_request_body_from_bytes(message, bodyType.c_str(), bytes);
    g_bytes_unref(bytes);
  }
  Response response;
  GBytes* answer = soup_session_send_and_read(session, message, nullptr, nullptr);
  response.status = soup_message_get_status(message);
  const char* type =
      soup_message_headers_get_content_type(soup_message_get_response_headers(message), nullptr);
  response.contentType = type ? type : "";
  const char* authenticate =
      soup_message_headers_get_list(soup_message_get_response_headers(message), "WWW-Authenticate");
  response.authenticate = authenticate ? authenticate : "";
  SoupMessageHeadersIter headerIter;
  soup_message_headers_iter_init(&headerIter, soup_message_get_response_headers(message));
  const char *name, *value;
  while (soup_message_headers_iter_next(&headerIter, &name, &value)) {
    gchar* lower = g_ascii_strdown(name, -1);
    response.headers[lower] = value;
    g_free(lower);
  }
  if (answer) {
    gsize size = 0;
    auto* data = static_cast<const char*>(g_bytes_get_data(answer, &size));
    response.body.assign(data, size);
    g_bytes_unref(answer);
  }
  g_object_unref(message);
  g_object_unref(session);
  return response;
}

}  // namespace wircam::testing
