// One page's drive mode: a WebSocket whose text messages (drive_command.h)
// steer one camera's vehicle through wirccontrol's `drive` action. Each
// command is answered with {"ack": seq, "obeyed": bool} so that the page
// can show the round trip; a malformed one is answered with {"error": ...}
// and sends neutral. When the socket closes the vehicle goes to neutral at
// once; when the page merely stops sending, wirccontrol's dead-man does it.
#pragma once

#include <libsoup/soup.h>

#include <functional>
#include <optional>
#include <string>

#include "fleet/drive_command.h"

namespace wircam::recorder {

class DriveSocket {
 public:
  using Drive = DriveFunction;

  // Takes a reference on `connection`; `closed` is called (main loop) once
  // it has closed, after the vehicle was sent neutral.
  DriveSocket(SoupWebsocketConnection* connection, Drive drive,
              std::function<void(DriveSocket*)> closed);
  ~DriveSocket();  // closes the socket if still open, without calling `closed`
  DriveSocket(const DriveSocket&) = delete;
  DriveSocket& operator=(const DriveSocket&) = delete;

 private:
  static void onMessage(SoupWebsocketConnection*, gint type, GBytes* message, gpointer self);
  static void onClosed(SoupWebsocketConnection*, gpointer self);
  void reply(const std::string& json);

  SoupWebsocketConnection* connection_;
  Drive drive_;
  std::function<void(DriveSocket*)> closed_;
  gulong messageHandler_ = 0, closedHandler_ = 0;
};

}  // namespace wircam::recorder
