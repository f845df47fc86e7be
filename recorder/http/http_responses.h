// The web server's plain answers: a body with its type, and errors as text
// or, for the API, as JSON that scripts can read; and a request's query
// values.
#pragma once

#include <libsoup/soup.h>

#include <nlohmann/json.hpp>
#include <string>

namespace wircam::recorder {

// A query parameter as libsoup decoded it, or null (also without a query).
inline const char* queryValue(GHashTable* query, const char* name) {
  return query ? static_cast<const char*>(g_hash_table_lookup(query, name)) : nullptr;
}

inline void respond(SoupServerMessage* message, guint status, const char* type,
                    const std::string& body) {
  soup_server_message_set_status(message, status, nullptr);
  soup_server_message_set_response(message, type, SOUP_MEMORY_COPY, body.data(), body.size());
}

inline void respondError(SoupServerMessage* message, guint status, const std::string& text) {
  respond(message, status, "text/plain; charset=utf-8", text + "\n");
}

// The API answers errors in JSON too, so scripts can read them.
inline void respondJsonError(SoupServerMessage* message, guint status, const std::string& text) {
  // The text may quote a path, which a client can make any bytes: bytes that
  // are not UTF-8 are replaced rather than thrown on.
  respond(message, status, "application/json",
          nlohmann::json{{"error", text}}.dump(-1, ' ', false,
                                               nlohmann::json::error_handler_t::replace));
}

// 405 with what the resource does serve (RFC 9110 15.5.6: Allow is required).
inline void respondMethodNotAllowed(SoupServerMessage* message, const char* allowed,
                                    const std::string& text) {
  soup_message_headers_replace(soup_server_message_get_response_headers(message), "Allow", allowed);
  respondJsonError(message, SOUP_STATUS_METHOD_NOT_ALLOWED, text);
}

}  // namespace wircam::recorder
