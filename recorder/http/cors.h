// Cross-origin reads for the fleet's page: a recorder's page shows the
// other recorders' cameras, fetching from them directly with their token in
// an Authorization header. Those resources answer a CORS preflight and
// carry Access-Control-Allow-Origin: * on every answer (401s included, so
// the page can tell a refused token from an unreachable recorder). `*` lets
// no cookie through (there is no Allow-Credentials): a page of another
// origin reads them only with the token itself. So only a recorder with a
// token shares them: one without (on 127.0.0.1 alone) would otherwise show
// its cameras to any web site its user's browser opens.
#pragma once

#include <libsoup/soup.h>

#include "http/http_routes.h"

namespace wircam::recorder {

// What other recorders' pages read: the cameras, their snapshots, the fleet.
inline bool sharedAcrossOrigins(Route::Kind kind) {
  return kind == Route::Kind::Cameras || kind == Route::Kind::Snapshot ||
         kind == Route::Kind::Fleet || kind == Route::Kind::Status;
}

inline void allowAnyOrigin(SoupServerMessage* message) {
  auto* headers = soup_server_message_get_response_headers(message);
  soup_message_headers_replace(headers, "Access-Control-Allow-Origin", "*");
}

// OPTIONS from a browser before a GET with an Authorization header.
inline void answerPreflight(SoupServerMessage* message) {
  allowAnyOrigin(message);
  auto* headers = soup_server_message_get_response_headers(message);
  soup_message_headers_replace(headers, "Access-Control-Allow-Methods", "GET");
  soup_message_headers_replace(headers, "Access-Control-Allow-Headers", "Authorization");
  soup_message_headers_replace(headers, "Access-Control-Max-Age", "600");
  soup_server_message_set_status(message, SOUP_STATUS_NO_CONTENT, nullptr);
}

}  // namespace wircam::recorder
