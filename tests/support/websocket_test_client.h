// libsoup's own WebSocket client on the default main context (run it with
// runMainLoopUntil): it connects with the given headers and subprotocols
// and keeps each text message it receives.
#pragma once

#include <libsoup/soup.h>

#include <string>
#include <utility>
#include <vector>

namespace wircam::testing {

// What a client asks for as it connects.
struct WebSocketTestOptions {
  std::vector<std::pair<std::string, std::string>> headers;
  std::vector<std::string> protocols;
  bool offerDeflate = false;  // permessage-deflate, as browsers offer it
};

class WebSocketTestClient {
 public:
  explicit WebSocketTestClient(const std::string& url, const WebSocketTestOptions& options = {}) {
    if (options.offerDeflate)
      soup_session_add_feature_by_type(session_, SOUP_TYPE_WEBSOCKET_EXTENSION_MANAGER);
    SoupMessage* message = soup_message_new("GET", url.c_str());
    for (const auto& [name, value] : options.headers)
      soup_message_headers_append(soup_message_get_request_headers(message), name.c_str(),
                                  value.c_str());
    std::vector<char*> protocols;
    for (const auto& protocol : options.protocols)
      protocols.push_back(const_cast<char*>(protocol.c_str()));
    protocols.push_back(nullptr);
    soup_session_websocket_connect_async(
        session_, message, nullptr, options.protocols.empty() ? nullptr : protocols.data(),
        G_PRIORITY_DEFAULT, nullptr, &WebSocketTestClient::onConnected, this);
    g_object_unref(message);
  }
  ~WebSocketTestClient() {
    if (connection) {
      g_signal_handlers_disconnect_matched(connection, G_SIGNAL_MATCH_DATA, 0, 0, nullptr, nullptr,
                                           this);
      g_object_unref(connection);
    }
    g_object_unref(session_);
  }
  WebSocketTestClient(const WebSocketTestClient&) = delete;
  WebSocketTestClient& operator=(const WebSocketTestClient&) = delete;

  bool open() const {
    return connection &&
           soup_websocket_connection_get_state(connection) == SOUP_WEBSOCKET_STATE_OPEN;
  }

  SoupWebsocketConnection* connection = nullptr;  // once connected
  bool failed = false;                            // the connection was refused
  std::vector<std::string> texts;                 // the text messages, in order
  std::vector<std::string> binaries;              // the binary ones, in order

 private:
  static void onConnected(GObject* source, GAsyncResult* result, gpointer self) {
    auto* client = static_cast<WebSocketTestClient*>(self);
    client->connection =
        soup_session_websocket_connect_finish(SOUP_SESSION(source), result, nullptr);
    client->failed = !client->connection;
    if (!client->connection) return;
    g_signal_connect(
        client->connection, "message",
        G_CALLBACK(+[](SoupWebsocketConnection*, gint type, GBytes* bytes, gpointer data) {
          gsize size = 0;
          auto* message = static_cast<const char*>(g_bytes_get_data(bytes, &size));
          auto* receiver = static_cast<WebSocketTestClient*>(data);
          (type == SOUP_WEBSOCKET_DATA_TEXT ? receiver->texts : receiver->binaries)
              .emplace_back(message, size);
        }),
        self);
  }

  SoupSession* session_ = soup_session_new();
};

}  // namespace wircam::testing
