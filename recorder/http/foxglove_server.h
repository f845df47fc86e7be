// The Foxglove WebSocket server (--foxglove): libsoup's WebSocket with the
// foxglove.websocket.v1 subprotocol, on its own port, behind the same
// connection limits, access token and TLS as the web server. Each client
// is a FoxgloveSession (http/foxglove_session.h); this file does the I/O.
//
// Bounded: at most Content::maxClients at once (one more is told why and
// closed); a message goes to a client only while its socket's send queue
// has room for it, so a client that reads slowly or not at all misses
// messages (counted; the newest frame goes once there is room) and never
// makes the recorder hold them. Main loop only, except for the frames,
// which come from the cameras' streaming threads.
#pragma once

#include <libsoup/soup.h>

#include <atomic>
#include <chrono>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common/expected.h"
#include "foxglove/foxglove_channels.h"
#include "foxglove/foxglove_protocol.h"
#include "http/foxglove_session.h"
#include "http/http_connections.h"
#include "live/live_servers.h"
#include "live/server_address.h"

namespace wircam::recorder {

class FoxgloveServer : public FoxgloveService {
 public:
  static Expected<std::unique_ptr<FoxgloveServer>, std::string> start(
      const ServerAddress& address, FoxgloveContent content, std::chrono::milliseconds idleTimeout);
  ~FoxgloveServer() override;
  FoxgloveServer(const FoxgloveServer&) = delete;
  FoxgloveServer& operator=(const FoxgloveServer&) = delete;

  const std::string& url() const override { return url_; }
  Stats stats() const override;
  void addCamera(const FoxgloveCamera& camera) override;
  void removeCamera(const std::string& name) override;
  void telemetry(const std::string& camera, const nlohmann::json& line, int64_t unixMs) override;
  void detections(const std::string& camera, const nlohmann::json& line, int64_t unixMs,
                  uint64_t framePts) override;
  void log(const std::string& camera, const std::string& message, int64_t unixMs) override;
  void pose(const std::string& camera, double x, double y, double z, int64_t unixMs) override;

  // A client's socket may hold this much unsent before it misses messages:
  // a few frames of 720p, so that a viewer that keeps up never misses one.
  static constexpr size_t kMaxUnsent = 512 * 1024;
  // What a client may send in one message (a subscription to every channel
  // of 256 cameras fits): a bigger one closes it with 1009 and the reason.
  // libsoup holds a message whole before it hands it on: past
  // kMaxBuffered it drops the connection itself, without a close frame.
  static constexpr size_t kMaxIncoming = 256 * 1024;
  static constexpr size_t kMaxBuffered = 1024 * 1024;

 private:
  struct Feed;    // a camera: its channels and its frames
  struct Client;  // a connection and its session
  explicit FoxgloveServer(FoxgloveContent content);

  static void onRequest(SoupServer*, SoupServerMessage* message, const char* path,
                        GHashTable* query, gpointer self);
  static void onWebSocket(SoupServer*, SoupServerMessage* message, const char* path,
                          SoupWebsocketConnection* connection, gpointer self);
  static void onMessage(SoupWebsocketConnection*, gint type, GBytes* message, gpointer client);
  static void onClosed(SoupWebsocketConnection*, gpointer client);

  bool authorised(SoupServerMessage* message, GHashTable* query) const;
  void obey(Client& client, const FoxgloveSession::Outcome& outcome);
  void drop(Client& client);
  void
  countImageSubscribers();  // for the streaming threads, which skip unwatched frames  // forgets it (main loop; the connection may still close)
  Feed* feedNamed(const std::string& name) const;
  std::vector<AdvertisedChannel> channelsOf(const Feed& feed) const;
  // Sends `frame` (built by messageDataHead) to every subscriber of the
  // channel with room for it, each under its own subscription id.
  void publish(uint32_t channel, std::string& frame, bool keyFrame = true, bool h264 = false);
  void publishJson(const std::string& camera, FoxgloveTopic topic, const nlohmann::json& message,
                   int64_t unixMs);
  void publishBytes(const std::string& camera, FoxgloveTopic topic, const std::string& message,
                    int64_t timeNs);
  void sendFrame(Feed& feed, GstSample* sample, int64_t utcNs);
  bool hasRoom(const Client& client, size_t bytes) const;
  bool watched(uint32_t channel) const;  // a client subscribes to it
  // The time a frame is stamped with, the same for its image and its tags:
  // whichever of the two comes first stamps it.
  static int64_t stampOf(Feed& feed, uint64_t pts, int64_t firstNs);

  FoxgloveContent content_;
  // Every channel a camera may have, for the advertisements to point at.
  const std::vector<FoxgloveChannel> kinds_ = foxgloveChannels({.positions = true});
  const FoxgloveChannel video_ = foxgloveChannels({.video = true}).front();
  SoupServer* server_ = nullptr;
  std::unique_ptr<HttpConnections> connections_;
  std::string url_, sessionId_;
  std::vector<std::unique_ptr<Feed>> feeds_;
  std::map<uint32_t, AdvertisedChannel> channels_;  // by id
  uint32_t nextChannel_ = 1;
  std::vector<std::unique_ptr<Client>> clients_;
  uint64_t refused_ = 0, sent_ = 0, dropped_ = 0;
  // Frames handed to the main loop check it first: the server may be gone.
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

}  // namespace wircam::recorder
