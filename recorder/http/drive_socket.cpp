#include "http/drive_socket.h"

#include "fleet/drive_command.h"

namespace wircam::recorder {

DriveSocket::DriveSocket(SoupWebsocketConnection* connection, Drive drive,
                         std::function<void(DriveSocket*)> closed)
    : connection_(SOUP_WEBSOCKET_CONNECTION(g_object_ref(connection))),
      drive_(std::move(drive)),
      closed_(std::move(closed)) {
  // A page sends a few dozen bytes a message: anything far bigger is hostile.
  soup_websocket_connection_set_max_incoming_payload_size(connection_, 4096);
  messageHandler_ = g_signal_connect(connection_, "message", G_CALLBACK(onMessage), this);
  closedHandler_ = g_signal_connect(connection_, "closed", G_CALLBACK(onClosed), this);
}

DriveSocket::~DriveSocket() {
  g_signal_handler_disconnect(connection_, messageHandler_);
  g_signal_handler_disconnect(connection_, closedHandler_);
  if (soup_websocket_connection_get_state(connection_) == SOUP_WEBSOCKET_STATE_OPEN) {
    drive_(0, 0);
    soup_websocket_connection_close(connection_, SOUP_WEBSOCKET_CLOSE_GOING_AWAY, "server stops");
  }
  g_object_unref(connection_);
}

void DriveSocket::reply(const std::string& json) {
  if (soup_websocket_connection_get_state(connection_) == SOUP_WEBSOCKET_STATE_OPEN)
    soup_websocket_connection_send_text(connection_, json.c_str());
}

void DriveSocket::onMessage(SoupWebsocketConnection*, gint type, GBytes* message, gpointer data) {
  auto* self = static_cast<DriveSocket*>(data);
  gsize size = 0;
  const char* bytes = static_cast<const char*>(g_bytes_get_data(message, &size));
  auto text = type == SOUP_WEBSOCKET_DATA_TEXT
                  ? std::optional<std::string_view>(std::string_view(bytes, size))
                  : std::nullopt;
  self->reply(obeyDriveMessage(text, self->drive_));
}

void DriveSocket::onClosed(SoupWebsocketConnection*, gpointer data) {
  auto* self = static_cast<DriveSocket*>(data);
  self->drive_(0, 0);
  // `closed` may delete this object: nothing after it.
  self->closed_(self);
}

}  // namespace wircam::recorder
