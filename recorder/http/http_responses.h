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

}  // namespace wircam::recorder
