#include "http/foxglove_server.h"

#include <algorithm>

#include "common/printable_text.h"
#include "http/foxglove_clients.h"
#include "http/http_responses.h"
#include "http/http_routes.h"
#include "log_line.h"
#include "webrtc/main_loop_call.h"

namespace wircam::recorder {

namespace {

constexpr guint kHttpUpgradeRequired = 426;  // not among libsoup's names

}  // namespace

FoxgloveServer::FoxgloveServer(FoxgloveContent content) : content_(std::move(content)) {}

Expected<std::unique_ptr<FoxgloveServer>, std::string> FoxgloveServer::start(
    const ServerAddress& address, FoxgloveContent content, std::chrono::milliseconds idleTimeout) {
  std::unique_ptr<FoxgloveServer> self(new FoxgloveServer(std::move(content)));
  self->server_ = soup_server_new("server-header", "wirc-recorder", nullptr);
  // Its messages are JPEG and H.264: deflating them costs CPU for nothing.
  soup_server_remove_websocket_extension(self->server_, SOUP_TYPE_WEBSOCKET_EXTENSION_DEFLATE);
  // Room for a client over the limit to be told so, and for stray requests.
  size_t slots = self->content_.maxClients + 4;
  auto connections = HttpConnections::listen(
      self->server_, address,
      {.maxOpen = slots, .maxPerAddress = slots, .idleTimeout = idleTimeout},
      {self->content_.certificateFile, self->content_.keyFile}, "--foxglove");
  if (!connections) return unexpected(connections.error());
  self->connections_ = std::move(*connections);
  self->url_ = std::string(self->connections_->tls() ? "wss://" : "ws://") + address.listenHost() +
               ":" + std::to_string(self->connections_->port()) + "/";
  // A client tells a restarted recorder by a new session id.
  self->sessionId_ = std::to_string(g_get_real_time());

  FoxgloveServer* raw = self.get();
  soup_server_add_early_handler(
      self->server_, nullptr,
      [](SoupServer*, SoupServerMessage* message, const char*, GHashTable*, gpointer data) {
        static_cast<FoxgloveServer*>(data)->connections_->requestStarted(message);
      },
      raw, nullptr);
  soup_server_add_handler(self->server_, nullptr, onRequest, raw, nullptr);
  const char* protocols[] = {kFoxgloveSubprotocol, nullptr};
  soup_server_add_websocket_handler(self->server_, nullptr, nullptr, const_cast<char**>(protocols),
                                    onWebSocket, raw, nullptr);
  auto ended = +[](SoupServer*, SoupServerMessage* message, gpointer data) {
    static_cast<FoxgloveServer*>(data)->connections_->requestEnded(message);
  };
  g_signal_connect(self->server_, "request-finished", G_CALLBACK(ended), raw);
  g_signal_connect(self->server_, "request-aborted", G_CALLBACK(ended), raw);
  for (const auto& camera : self->content_.cameras) self->addCamera(camera);
  return self;
}

FoxgloveServer::~FoxgloveServer() {
  alive_.reset();
  // A removed camera's feed forgot its frames already (they may be gone).
  for (const auto& feed : feeds_)
    if (!feed->channels.empty()) feed->camera.frames->forget(feed->listener);
  while (!clients_.empty()) {
    Client& client = *clients_.back();
    // Its vehicles are not left on a last command.
    for (const auto& camera : client.session.drivenCameras()) content_.drive(camera, 0, 0);
    if (soup_websocket_connection_get_state(client.connection) == SOUP_WEBSOCKET_STATE_OPEN)
      soup_websocket_connection_close(client.connection, SOUP_WEBSOCKET_CLOSE_GOING_AWAY,
                                      "the recorder stops");
    drop(client);
  }
  if (server_) {
    soup_server_disconnect(server_);
    g_object_unref(server_);
  }
}

FoxgloveService::Stats FoxgloveServer::stats() const {
  return {.clients = clients_.size(), .refused = refused_, .sent = sent_, .dropped = dropped_};
}

bool FoxgloveServer::authorised(SoupServerMessage* message, GHashTable* query) const {
  auto* headers = soup_server_message_get_request_headers(message);
  if (carriesToken(soup_message_headers_get_one(headers, "Authorization"),
                   soup_message_headers_get_one(headers, "Cookie"), content_.token))
    return true;
  // Foxglove and Lichtblick open a URL and send no header of their own:
  // ws://HOST:PORT/?token=T
  const char* token = queryValue(query, "token");
  return token && carriesToken(("Bearer " + std::string(token)).c_str(), nullptr, content_.token);
}

void FoxgloveServer::onRequest(SoupServer*, SoupServerMessage* message, const char*,
                               GHashTable* query, gpointer data) {
  auto* self = static_cast<FoxgloveServer*>(data);
  if (!self->authorised(message, query))
    return respondJsonError(message, SOUP_STATUS_UNAUTHORIZED,
                            "needs the access token: Authorization: Bearer T, or ?token=T in the "
                            "URL");
  auto* headers = soup_server_message_get_request_headers(message);
  if (!soup_message_headers_header_contains(headers, "Upgrade", "websocket")) {
    respondJsonError(message, kHttpUpgradeRequired,
                     std::string("a Foxglove WebSocket (") + kFoxgloveSubprotocol + "): open " +
                         self->url_ + " in Foxglove or Lichtblick");
    soup_server_message_set_status(message, kHttpUpgradeRequired, "Upgrade Required");
    return;
  }
  // libsoup would take a client that offers no subprotocol at all.
  if (!soup_message_headers_header_contains(headers, "Sec-WebSocket-Protocol",
                                            kFoxgloveSubprotocol))
    return respondJsonError(message, SOUP_STATUS_BAD_REQUEST,
                            std::string("this server speaks the ") + kFoxgloveSubprotocol +
                                " subprotocol only: offer it (Sec-WebSocket-Protocol)");
  // Left unanswered: libsoup upgrades it (onWebSocket).
  self->connections_->upgrading(message);
}

void FoxgloveServer::onWebSocket(SoupServer*, SoupServerMessage* message, const char*,
                                 SoupWebsocketConnection* connection, gpointer data) {
  auto* self = static_cast<FoxgloveServer*>(data);
  GSocketAddress* remote = soup_server_message_get_remote_address(message);
  gchar* peer = remote ? g_socket_connectable_to_string(G_SOCKET_CONNECTABLE(remote)) : nullptr;
  std::string who = peer ? peer : "a client";
  g_free(peer);
  if (self->clients_.size() >= self->content_.maxClients) {
    ++self->refused_;
    size_t most = self->content_.maxClients;
    std::string why = "this recorder serves at most " + std::to_string(most) + " Foxglove client" +
                      (most == 1 ? "" : "s") + " at once; try again later";
    soup_websocket_connection_send_text(connection,
                                        statusMessage(FoxgloveStatusLevel::Error, why).c_str());
    // Kept until its close handshake is over, so that the reason arrives.
    g_signal_connect(g_object_ref(connection), "closed",
                     G_CALLBACK(+[](SoupWebsocketConnection* closed, gpointer) {
                       g_idle_add(
                           [](gpointer c) {
                             g_object_unref(c);
                             return G_SOURCE_REMOVE;
                           },
                           closed);
                     }),
                     nullptr);
    // 1008: libsoup sends none of the codes after 1011 (1013 would say "try
    // again later"); the status message before it says so.
    soup_websocket_connection_close(connection, SOUP_WEBSOCKET_CLOSE_POLICY_VIOLATION,
                                    "too many clients");
    logLine("Foxglove: refused " + who + ": " + why);
    return;
  }
  auto client = std::make_unique<Client>(Client{
      .server = self,
      .connection = SOUP_WEBSOCKET_CONNECTION(g_object_ref(connection)),
      .socket = nullptr,
      .peer = who,
      .session = FoxgloveSession({
          .isChannel = [self](uint32_t id) { return self->channels_.contains(id); },
          .isCamera = [self](const std::string& name) { return self->feedNamed(name) != nullptr; },
          .isDrivable = [self](const std::string& name) { return self->content_.drivable(name); },
          .canDrive = !self->content_.token.empty(),
      })});
  if (GSocket* socket = self->connections_->socketOf(message))
    client->socket = G_SOCKET(g_object_ref(socket));
  soup_websocket_connection_set_max_incoming_payload_size(connection, kMaxBuffered);
  Client* raw = client.get();
  client->messageHandler = g_signal_connect(connection, "message", G_CALLBACK(onMessage), raw);
  client->closedHandler = g_signal_connect(connection, "closed", G_CALLBACK(onClosed), raw);
  std::vector<std::string> capabilities;
  if (!self->content_.token.empty()) capabilities.push_back("clientPublish");
  soup_websocket_connection_send_text(
      connection, serverInfoMessage("wirc-recorder " + self->content_.version, capabilities,
                                    {{"maxClients", std::to_string(self->content_.maxClients)},
                                     {"clients", std::to_string(self->clients_.size() + 1)}},
                                    self->sessionId_)
                      .c_str());
  std::vector<AdvertisedChannel> all;
  for (const auto& feed : self->feeds_)
    for (auto& channel : self->channelsOf(*feed)) all.push_back(channel);
  if (!all.empty()) soup_websocket_connection_send_text(connection, advertiseMessage(all).c_str());
  self->clients_.push_back(std::move(client));
  logLine("Foxglove: " + who + " connected (" + std::to_string(self->clients_.size()) + " of " +
          std::to_string(self->content_.maxClients) + ")");
}

void FoxgloveServer::onMessage(SoupWebsocketConnection*, gint type, GBytes* message,
                               gpointer data) {
  auto& client = *static_cast<Client*>(data);
  gsize size = 0;
  const char* bytes = static_cast<const char*>(g_bytes_get_data(message, &size));
  std::string_view view(bytes, size);
  if (size > kMaxIncoming) {
    std::string why =
        "a message of " + std::to_string(size) + " bytes; at most " + std::to_string(kMaxIncoming);
    logLine("Foxglove: closed " + client.peer + ": " + why);
    for (const auto& camera : client.session.drivenCameras())
      client.server->content_.drive(camera, 0, 0);
    soup_websocket_connection_close(client.connection, SOUP_WEBSOCKET_CLOSE_TOO_BIG, why.c_str());
    return;
  }
  client.server->obey(client, type == SOUP_WEBSOCKET_DATA_TEXT ? client.session.text(view)
                                                               : client.session.binary(view));
}

void FoxgloveServer::obey(Client& client, const FoxgloveSession::Outcome& outcome) {
  for (const auto& drive : outcome.drives) {
    bool obeyed = content_.drive(drive.camera, drive.steering, drive.throttle).value_or(false);
    // Said once, until the vehicle obeys again: not ten times a second.
    bool told = client.disobeyed.contains(drive.camera);
    if (obeyed) client.disobeyed.erase(drive.camera);
    if (obeyed || told || outcome.close) continue;
    client.disobeyed.insert(drive.camera);
    soup_websocket_connection_send_text(
        client.connection,
        statusMessage(FoxgloveStatusLevel::Warning,
                      drive.camera + "'s vehicle does not obey: the recorder does not hold its "
                                     "control right (request-control: docs/foxglove.md)")
            .c_str());
  }
  for (const auto& reply : outcome.replies)
    soup_websocket_connection_send_text(client.connection, reply.c_str());
  // Subscriptions to H.264 start at a key frame.
  for (auto& [channel, decoding] : client.decoding)
    if (!client.session.subscriptionTo(channel)) decoding = false;
  if (outcome.close) {
    logLine("Foxglove: closed " + client.peer + ": " + printableText(*outcome.close));
    std::string reason = outcome.close->substr(0, 120);  // a close frame holds 123 bytes
    soup_websocket_connection_close(client.connection, SOUP_WEBSOCKET_CLOSE_POLICY_VIOLATION,
                                    reason.c_str());
  }
  countImageSubscribers();
}

void FoxgloveServer::countImageSubscribers() {
  for (const auto& feed : feeds_) {
    auto image = feed->channels.find(FoxgloveTopic::Image);
    int subscribers = 0;
    for (const auto& c : clients_)
      if (image != feed->channels.end() && c->session.subscriptionTo(image->second)) ++subscribers;
    feed->imageSubscribers = subscribers;
  }
}

void FoxgloveServer::onClosed(SoupWebsocketConnection*, gpointer data) {
  auto& client = *static_cast<Client*>(data);
  FoxgloveServer* self = client.server;
  for (const auto& camera : client.session.drivenCameras()) self->content_.drive(camera, 0, 0);
  std::string dropped =
      client.dropped ? " (" + std::to_string(client.dropped) + " messages it had no room for)" : "";
  // How it ended, as libsoup saw it: 1006 when the connection just went.
  gushort code = soup_websocket_connection_get_close_code(client.connection);
  const char* reason = soup_websocket_connection_get_close_data(client.connection);
  std::string how = code == 0 ? "" : ", " + std::to_string(code);
  if (reason && *reason) how += " " + printableText(reason);
  logLine("Foxglove: " + client.peer + " left" + how + dropped);
  self->drop(client);
  self->countImageSubscribers();
}

void FoxgloveServer::drop(Client& client) {
  g_signal_handler_disconnect(client.connection, client.messageHandler);
  g_signal_handler_disconnect(client.connection, client.closedHandler);
  g_object_unref(client.connection);
  g_clear_object(&client.socket);
  std::erase_if(clients_, [&](const auto& c) { return c.get() == &client; });
}

FoxgloveServer::Feed* FoxgloveServer::feedNamed(const std::string& name) const {
  // A removed camera's feed stays (frames may be on their way to it) with
  // no channels: it is not that camera any more.
  for (const auto& feed : feeds_)
    if (feed->camera.name == name && !feed->channels.empty()) return feed.get();
  return nullptr;
}

std::vector<AdvertisedChannel> FoxgloveServer::channelsOf(const Feed& feed) const {
  std::vector<AdvertisedChannel> list;
  for (const auto& [topic, id] : feed.channels) list.push_back(channels_.at(id));
  return list;
}

void FoxgloveServer::addCamera(const FoxgloveCamera& camera) {
  if (feedNamed(camera.name)) return;
  auto feed = std::make_unique<Feed>();
  feed->camera = camera;
  feed->h264 = camera.encoded != nullptr;
  if (feed->h264) feed->camera.frames = camera.encoded;
  for (const auto& kind : kinds_) {
    if (kind.topic == FoxgloveTopic::Pose && !camera.positions) continue;
    uint32_t id = nextChannel_++;
    const FoxgloveChannel* channel =
        kind.topic == FoxgloveTopic::Image && feed->h264 ? &video_ : &kind;
    channels_.emplace(id, AdvertisedChannel{id, foxgloveTopicName(camera.name, kind), channel});
    feed->channels[kind.topic] = id;
  }
  Feed* raw = feed.get();
  // Frames come on the streaming thread; clients live on the main loop.
  feed->listener = feed->camera.frames->listen([this, raw](GstSample* sample) {
    if (raw->imageSubscribers.load() == 0) return;
    std::shared_ptr<GstSample> held(gst_sample_ref(sample), gst_sample_unref);
    // The frame's own time, as the recording keeps it: not its arrival here.
    int64_t arrivedNs = raw->camera.frames->wallTimeNs(sample);
    callOnMainLoop(alive_,
                   [this, raw, held, arrivedNs] { sendFrame(*raw, held.get(), arrivedNs); });
  });
  feeds_.push_back(std::move(feed));
  auto advertisement = advertiseMessage(channelsOf(*raw));
  for (const auto& client : clients_)
    soup_websocket_connection_send_text(client->connection, advertisement.c_str());
}

void FoxgloveServer::removeCamera(const std::string& name) {
  Feed* feed = feedNamed(name);
  if (!feed) return;
  feed->camera.frames->forget(feed->listener);
  std::vector<uint32_t> ids;
  for (const auto& [topic, id] : feed->channels) {
    ids.push_back(id);
    channels_.erase(id);
    for (const auto& client : clients_) client->session.channelGone(id);
  }
  auto unadvertisement = unadvertiseMessage(ids);
  for (const auto& client : clients_)
    soup_websocket_connection_send_text(client->connection, unadvertisement.c_str());
  // Frames already on their way to the main loop hold the feed: it goes
  // with the server, not before (a camera removed is rare; its feed is small).
  feed->imageSubscribers = 0;
  feed->channels.clear();
}

}  // namespace wircam::recorder
