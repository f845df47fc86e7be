#include "http/http_connections.h"

#include <algorithm>

#include "http/head_watch_stream.h"

namespace wircam::recorder {

namespace {

ConnectionSlots::Clock::time_point now() { return ConnectionSlots::Clock::now(); }

// The client's IP address ("" if not IP).
std::string hostOf(GSocketAddress* address) {
  if (!G_IS_INET_SOCKET_ADDRESS(address)) return "";
  gchar* host =
      g_inet_address_to_string(g_inet_socket_address_get_address(G_INET_SOCKET_ADDRESS(address)));
  std::string text = host;
  g_free(host);
  return text;
}

// "address:port": one TCP connection's client end.
std::string endpointOf(GSocketAddress* address) {
  if (!G_IS_INET_SOCKET_ADDRESS(address)) return "";
  return hostOf(address) + ":" +
         std::to_string(g_inet_socket_address_get_port(G_INET_SOCKET_ADDRESS(address)));
}

struct GoneWatch {
  HttpConnections* owner;
  std::string endpoint;
  GSocketConnection* connection;
  std::weak_ptr<bool> alive;
};

}  // namespace

HttpConnections::HttpConnections(SoupServer* server, ConnectionSlots::Limits limits)
    : server_(server),
      slots_(limits),
      socketTimeoutSeconds_(static_cast<guint>(std::max<int64_t>(
          1, (std::chrono::duration_cast<std::chrono::milliseconds>(limits.idleTimeout).count() +
              999) /
                 1000))) {}

Expected<std::unique_ptr<HttpConnections>, std::string> HttpConnections::listen(
    SoupServer* server, const ServerAddress& address, ConnectionSlots::Limits limits,
    const Tls& tls, const std::string& option) {
  std::unique_ptr<HttpConnections> self(new HttpConnections(server, limits));
  if (!tls.certificateFile.empty()) {
    GError* error = nullptr;
    self->certificate_ =
        g_tls_certificate_new_from_files(tls.certificateFile.c_str(), tls.keyFile.c_str(), &error);
    if (!self->certificate_) {
      std::string text = error->message;
      g_error_free(error);
      return unexpected("--http-cert " + tls.certificateFile + ", --http-key " + tls.keyFile +
                        ": " + text);
    }
  }
  GSocketAddress* socket =
      g_inet_socket_address_new_from_string(address.listenHost().c_str(), address.port);
  if (!socket) return unexpected(option + ": '" + address.host + "' is not an IP address");
  auto problem = self->listenOn(socket);
  g_object_unref(socket);
  if (problem)
    return unexpected(option + ": cannot listen on port " + std::to_string(address.port) + ": " +
                      *problem);
  return self;
}

std::optional<std::string> HttpConnections::listenOn(GSocketAddress* address) {
  service_ = g_socket_service_new();
  // GLib's default backlog (10) drops the SYNs of a burst of clients, who
  // then wait seconds to retry: let a whole cap's worth queue.
  g_socket_listener_set_backlog(G_SOCKET_LISTENER(service_),
                                static_cast<int>(slots_.limits().maxOpen));
  GSocketAddress* bound = nullptr;
  GError* error = nullptr;
  if (!g_socket_listener_add_address(G_SOCKET_LISTENER(service_), address, G_SOCKET_TYPE_STREAM,
                                     G_SOCKET_PROTOCOL_TCP, nullptr, &bound, &error)) {
    std::string text = error->message;
    g_error_free(error);
    return text;
  }
  port_ = g_inet_socket_address_get_port(G_INET_SOCKET_ADDRESS(bound));
  g_object_unref(bound);
  g_signal_connect(service_, "incoming", G_CALLBACK(onIncoming), this);
  g_socket_service_start(service_);
  sweep_ = g_timeout_add(static_cast<guint>(kSweepInterval.count()), onSweep, this);
  return std::nullopt;
}

HttpConnections::~HttpConnections() {
  alive_.reset();
  if (sweep_) g_source_remove(sweep_);
  if (service_) {
    g_socket_service_stop(service_);
    g_socket_listener_close(G_SOCKET_LISTENER(service_));
    g_object_unref(service_);
  }
  g_clear_object(&certificate_);
}

gboolean HttpConnections::onIncoming(GSocketService*, GSocketConnection* connection, GObject*,
                                     gpointer data) {
  auto* self = static_cast<HttpConnections*>(data);
  GSocketAddress* remote = g_socket_connection_get_remote_address(connection, nullptr);
  std::string endpoint = remote ? endpointOf(remote) : "";
  auto slot = remote ? self->slots_.admit(hostOf(remote), now()) : std::nullopt;
  if (!slot) {
    g_clear_object(&remote);
    g_io_stream_close(G_IO_STREAM(connection), nullptr, nullptr);
    return TRUE;
  }
  GSocket* socket = g_socket_connection_get_socket(connection);
  // Writes to a client that stopped reading give up after this long.
  g_socket_set_timeout(socket, self->socketTimeoutSeconds_);
  self->accepted_[endpoint] = {connection, socket, *slot};
  g_object_weak_ref(G_OBJECT(connection), onConnectionGone,
                    new GoneWatch{self, endpoint, connection, self->alive_});
  g_clear_object(&remote);
  self->handOn(connection);
  return TRUE;
}

void HttpConnections::onConnectionGone(gpointer data, GObject*) {
  std::unique_ptr<GoneWatch> watch(static_cast<GoneWatch*>(data));
  if (watch->alive.expired()) return;
  auto& accepted = watch->owner->accepted_;
  auto it = accepted.find(watch->endpoint);
  // (The sweep may have let it go already, once it saw it closed.)
  if (it == accepted.end() || it->second.connection != watch->connection) return;
  watch->owner->slots_.closed(it->second.slot);
  accepted.erase(it);
}

gboolean HttpConnections::onSweep(gpointer data) {
  auto* self = static_cast<HttpConnections*>(data);
  // Closed by either side but not yet let go by libsoup: the slot is free.
  for (auto it = self->accepted_.begin(); it != self->accepted_.end();) {
    if (g_io_stream_is_closed(G_IO_STREAM(it->second.connection))) {
      self->slots_.closed(it->second.slot);
      it = self->accepted_.erase(it);
    } else {
      ++it;
    }
  }
  auto due = self->slots_.expired(now());
  for (auto& [endpoint, accepted] : self->accepted_)
    if (std::find(due.begin(), due.end(), accepted.slot) != due.end())
      // libsoup, reading, sees the end and lets the connection go.
      g_socket_shutdown(accepted.socket, TRUE, TRUE, nullptr);
  return G_SOURCE_CONTINUE;
}

void HttpConnections::handOn(GSocketConnection* connection) {
  GSocketAddress* local = g_socket_connection_get_local_address(connection, nullptr);
  GSocketAddress* remote = g_socket_connection_get_remote_address(connection, nullptr);
  GError* error = nullptr;
  // HTTPS: libsoup gets the TLS stream over the connection (which it keeps
  // alive: the slot is still the connection's). The handshake happens on
  // the first read. Plain or not, each request head it reads is within its
  // bound or answered 414/431 (head_watch_stream.h).
  GIOStream* stream = G_IO_STREAM(g_object_ref(connection));
  if (certificate_) {
    GIOStream* tls = g_tls_server_connection_new(stream, certificate_, &error);
    g_object_unref(stream);
    stream = tls;
  }
  if (stream) {
    GIOStream* watched = watchRequestHeads(stream, connection);
    g_object_unref(stream);
    stream = watched;
  }
  if (!stream || !local || !remote ||
      !soup_server_accept_iostream(server_, stream, local, remote, &error))
    g_io_stream_close(G_IO_STREAM(connection), nullptr, nullptr);
  g_clear_error(&error);
  g_clear_object(&stream);
  g_clear_object(&local);
  g_clear_object(&remote);
}

const HttpConnections::Accepted* HttpConnections::find(SoupServerMessage* message) const {
  GSocketAddress* remote = soup_server_message_get_remote_address(message);
  if (!remote) return nullptr;
  auto it = accepted_.find(endpointOf(remote));
  return it == accepted_.end() ? nullptr : &it->second;
}

GSocket* HttpConnections::socketOf(SoupServerMessage* message) const {
  const Accepted* accepted = find(message);
  return accepted ? accepted->socket : nullptr;
}

void HttpConnections::requestStarted(SoupServerMessage* message) {
  if (const Accepted* accepted = find(message)) slots_.requestStarted(accepted->slot);
}

void HttpConnections::requestEnded(SoupServerMessage* message) {
  if (const Accepted* accepted = find(message)) slots_.requestEnded(accepted->slot, now());
}

void HttpConnections::upgrading(SoupServerMessage* message) {
  if (const Accepted* accepted = find(message)) {
    slots_.upgraded(accepted->slot);
    g_socket_set_timeout(accepted->socket, 0);
  }
}

}  // namespace wircam::recorder
