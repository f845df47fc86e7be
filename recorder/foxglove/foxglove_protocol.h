// The Foxglove WebSocket protocol (foxglove.websocket.v1, foxglove/ws-protocol
// docs/spec.md), the server's side as bytes: its messages to clients, and
// the clients' messages parsed. No socket here (http/foxglove_server.h has
// it; http/foxglove_session.h keeps a client's state).
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "common/expected.h"
#include "foxglove/foxglove_channels.h"

namespace wircam::recorder {

inline constexpr const char* kFoxgloveSubprotocol = "foxglove.websocket.v1";

// A server channel as advertised: its id, topic and what it carries.
struct AdvertisedChannel {
  uint32_t id;
  std::string topic;
  const FoxgloveChannel* channel;  // borrowed
};

enum class FoxgloveStatusLevel { Info = 0, Warning = 1, Error = 2 };

std::string serverInfoMessage(const std::string& name, const std::vector<std::string>& capabilities,
                              const std::map<std::string, std::string>& metadata,
                              const std::string& sessionId);
// Protobuf schemas go in base64, JSON schemas as their text.
std::string advertiseMessage(const std::vector<AdvertisedChannel>& channels);
std::string unadvertiseMessage(const std::vector<uint32_t>& channelIds);
std::string statusMessage(FoxgloveStatusLevel level, const std::string& message);

// The head of a binary Message Data frame (opcode 1, the subscription id,
// the timestamp in ns, little-endian); the message's bytes follow it.
std::string messageDataHead(uint32_t subscriptionId, uint64_t timestampNs);
inline constexpr size_t kMessageDataHeadSize = 13;
// Rewrites the subscription id of a frame built by messageDataHead: one
// message, built once, goes to each subscriber under its own id.
void setSubscriptionId(std::string& frame, uint32_t subscriptionId);

// What a client says.
struct ClientSubscribe {
  std::vector<std::pair<uint32_t, uint32_t>> subscriptions;  // (id, channelId)
};
struct ClientUnsubscribe {
  std::vector<uint32_t> subscriptionIds;
};
struct ClientChannel {
  uint32_t id;
  std::string topic, encoding, schemaName;
};
struct ClientAdvertise {
  std::vector<ClientChannel> channels;
};
struct ClientUnadvertise {
  std::vector<uint32_t> channelIds;
};
using ClientTextMessage =
    std::variant<ClientSubscribe, ClientUnsubscribe, ClientAdvertise, ClientUnadvertise>;

// A text message, or why it is not one this server takes (not JSON, no
// op, an op it does not serve, a field missing or of the wrong type).
Expected<ClientTextMessage, std::string> parseClientText(std::string_view text);

// A binary Client Message Data (opcode 1): its channel and payload.
struct ClientMessageData {
  uint32_t channelId;
  std::string_view payload;
};
Expected<ClientMessageData, std::string> parseClientBinary(std::string_view bytes);

}  // namespace wircam::recorder
