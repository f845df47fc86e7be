// The web server's listening socket, accepting connections itself and
// handing each one admitted by ConnectionSlots to libsoup
// (soup_server_accept_iostream), so that every connection is counted from
// the moment it is accepted to the moment it is gone, however it ends
// (libsoup's request signals miss a connection closed before its first
// request line). Idle and half-open connections are closed by a sweep every
// kSweepInterval. Main loop only.
#pragma once

#include <libsoup/soup.h>

#include <chrono>
#include <map>
#include <memory>
#include <string>

#include "common/expected.h"
#include "http/connection_slots.h"
#include "live/server_address.h"

namespace wircam::recorder {

class HttpConnections {
 public:
  // PEM files of a server's certificate and its key; empty: plain HTTP.
  struct Tls {
    std::string certificateFile, keyFile;
  };
  // Listens on `address` for `server`; the port bound comes with it. With
  // a certificate every connection is TLS: the handshake first, then HTTP
  // inside it; a client that speaks plain HTTP fails the handshake and is
  // closed. Why not, in the words of the `option` that asked ("--http").
  static Expected<std::unique_ptr<HttpConnections>, std::string> listen(
      SoupServer* server, const ServerAddress& address, ConnectionSlots::Limits limits,
      const Tls& tls, const std::string& option);
  ~HttpConnections();
  HttpConnections(const HttpConnections&) = delete;
  HttpConnections& operator=(const HttpConnections&) = delete;

  uint16_t port() const { return port_; }
  bool tls() const { return certificate_ != nullptr; }
  // What libsoup tells of a message's request on one of these connections.
  void requestStarted(SoupServerMessage* message);
  void requestEnded(SoupServerMessage* message);
  // The request is let through to become a WebSocket: its connection is
  // busy until it closes, and no write timeout applies.
  void upgrading(SoupServerMessage* message);
  // The message's connection, for answering on it directly (libsoup does
  // not know the socket of a connection it was handed).
  GSocket* socketOf(SoupServerMessage* message) const;

  size_t open() const { return slots_.open(); }
  uint64_t refused() const { return slots_.refused(); }

  static constexpr std::chrono::milliseconds kSweepInterval{250};

 private:
  HttpConnections(SoupServer* server, ConnectionSlots::Limits limits);
  // The listening itself, once the address and certificate are read.
  std::optional<std::string> listenOn(GSocketAddress* address);
  static gboolean onIncoming(GSocketService*, GSocketConnection* connection, GObject*,
                             gpointer self);
  static void onConnectionGone(gpointer data, GObject* connection);
  // The connection to libsoup (over TLS with a certificate).
  void handOn(GSocketConnection* connection);
  static gboolean onSweep(gpointer self);
  struct Accepted {
    GSocketConnection* connection;  // weak: libsoup owns it
    GSocket* socket;
    ConnectionSlots::Id slot;
  };
  const Accepted* find(SoupServerMessage* message) const;
  SoupServer* server_;
  GTlsCertificate* certificate_ = nullptr;  // owned; null: plain HTTP
  ConnectionSlots slots_;
  GSocketService* service_ = nullptr;
  guint sweep_ = 0;
  uint16_t port_ = 0;
  guint socketTimeoutSeconds_;
  std::map<std::string, Accepted> accepted_;  // by the client's "address:port"
  // Weak-reference callbacks may run after this object is gone (a
  // connection libsoup frees later): they check this first.
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

}  // namespace wircam::recorder
