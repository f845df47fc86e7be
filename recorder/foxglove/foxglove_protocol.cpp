#include "foxglove/foxglove_protocol.h"

#include <glib.h>

#include <nlohmann/json.hpp>

namespace wircam::recorder {

namespace {

void putLittleEndian(std::string& out, size_t at, uint64_t value, size_t bytes) {
  for (size_t i = 0; i < bytes; ++i) out[at + i] = static_cast<char>(value >> (8 * i) & 0xff);
}

std::string base64(std::string_view bytes) {
  gchar* text = g_base64_encode(reinterpret_cast<const guchar*>(bytes.data()), bytes.size());
  std::string out(text);
  g_free(text);
  return out;
}

// The unsigned 32-bit integer `field` of `object`, or why not.
Expected<uint32_t, std::string> idIn(const nlohmann::json& object, const char* field) {
  auto it = object.find(field);
  if (it == object.end() || !it->is_number_unsigned() || it->get<uint64_t>() > UINT32_MAX)
    return unexpected(std::string("'") + field + "' is not an unsigned 32-bit integer");
  return it->get<uint32_t>();
}

Expected<std::string, std::string> textIn(const nlohmann::json& object, const char* field) {
  auto it = object.find(field);
  if (it == object.end() || !it->is_string())
    return unexpected(std::string("'") + field + "' is not a string");
  return it->get<std::string>();
}

Expected<std::vector<uint32_t>, std::string> idsIn(const nlohmann::json& message,
                                                   const char* field) {
  auto it = message.find(field);
  if (it == message.end() || !it->is_array())
    return unexpected(std::string("'") + field + "' is not an array");
  std::vector<uint32_t> ids;
  for (const auto& id : *it) {
    if (!id.is_number_unsigned() || id.get<uint64_t>() > UINT32_MAX)
      return unexpected(std::string("'") + field + "' holds something other than ids");
    ids.push_back(id.get<uint32_t>());
  }
  return ids;
}

// Each object of the array `field`, read by `read`.
template <typename T, typename Read>
Expected<std::vector<T>, std::string> objectsIn(const nlohmann::json& message, const char* field,
                                                Read read) {
  auto it = message.find(field);
  if (it == message.end() || !it->is_array())
    return unexpected(std::string("'") + field + "' is not an array");
  std::vector<T> out;
  for (const auto& object : *it) {
    if (!object.is_object())
      return unexpected(std::string("'") + field + "' holds something other than objects");
    auto item = read(object);
    if (!item) return unexpected(item.error());
    out.push_back(std::move(*item));
  }
  return out;
}

Expected<std::pair<uint32_t, uint32_t>, std::string> subscriptionIn(const nlohmann::json& object) {
  auto id = idIn(object, "id");
  if (!id) return unexpected(id.error());
  auto channel = idIn(object, "channelId");
  if (!channel) return unexpected(channel.error());
  return std::pair(*id, *channel);
}

Expected<ClientChannel, std::string> clientChannelIn(const nlohmann::json& object) {
  auto id = idIn(object, "id");
  if (!id) return unexpected(id.error());
  ClientChannel channel{.id = *id};
  for (auto [field, value] :
       {std::pair("topic", &channel.topic), std::pair("encoding", &channel.encoding)}) {
    auto text = textIn(object, field);
    if (!text) return unexpected(text.error());
    *value = *text;
  }
  // Optional in the protocol (a ROS 1 client may leave it out).
  channel.schemaName = object.value("schemaName", "");
  return channel;
}

}  // namespace

std::string serverInfoMessage(const std::string& name, const std::vector<std::string>& capabilities,
                              const std::map<std::string, std::string>& metadata,
                              const std::string& sessionId) {
  return nlohmann::json{{"op", "serverInfo"},           {"name", name},
                        {"capabilities", capabilities}, {"supportedEncodings", {"json"}},
                        {"metadata", metadata},         {"sessionId", sessionId}}
      .dump();
}

std::string advertiseMessage(const std::vector<AdvertisedChannel>& channels) {
  nlohmann::json list = nlohmann::json::array();
  for (const auto& c : channels) {
    bool binary = c.channel->schemaEncoding == "protobuf";
    list.push_back({{"id", c.id},
                    {"topic", c.topic},
                    {"encoding", c.channel->encoding},
                    {"schemaName", c.channel->schemaName},
                    {"schema", binary ? base64(c.channel->schema) : c.channel->schema},
                    {"schemaEncoding", c.channel->schemaEncoding}});
  }
  return nlohmann::json{{"op", "advertise"}, {"channels", list}}.dump();
}

std::string unadvertiseMessage(const std::vector<uint32_t>& channelIds) {
  return nlohmann::json{{"op", "unadvertise"}, {"channelIds", channelIds}}.dump();
}

std::string statusMessage(FoxgloveStatusLevel level, const std::string& message) {
  return nlohmann::json{{"op", "status"}, {"level", static_cast<int>(level)}, {"message", message}}
      .dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

std::string messageDataHead(uint32_t subscriptionId, uint64_t timestampNs) {
  std::string head(kMessageDataHeadSize, '\0');
  head[0] = 1;
  putLittleEndian(head, 1, subscriptionId, 4);
  putLittleEndian(head, 5, timestampNs, 8);
  return head;
}

void setSubscriptionId(std::string& frame, uint32_t subscriptionId) {
  putLittleEndian(frame, 1, subscriptionId, 4);
}

Expected<ClientTextMessage, std::string> parseClientText(std::string_view text) {
  auto message = nlohmann::json::parse(text, nullptr, false);
  if (message.is_discarded() || !message.is_object()) return unexpected("not a JSON object");
  auto op = textIn(message, "op");
  if (!op) return unexpected(op.error());
  if (*op == "subscribe") {
    auto list = objectsIn<std::pair<uint32_t, uint32_t>>(message, "subscriptions", subscriptionIn);
    if (!list) return unexpected(list.error());
    return ClientTextMessage(ClientSubscribe{std::move(*list)});
  }
  if (*op == "unsubscribe") {
    auto ids = idsIn(message, "subscriptionIds");
    if (!ids) return unexpected(ids.error());
    return ClientTextMessage(ClientUnsubscribe{std::move(*ids)});
  }
  if (*op == "advertise") {
    auto list = objectsIn<ClientChannel>(message, "channels", clientChannelIn);
    if (!list) return unexpected(list.error());
    return ClientTextMessage(ClientAdvertise{std::move(*list)});
  }
  if (*op == "unadvertise") {
    auto ids = idsIn(message, "channelIds");
    if (!ids) return unexpected(ids.error());
    return ClientTextMessage(ClientUnadvertise{std::move(*ids)});
  }
  return unexpected("op '" + op->substr(0, 40) + "' is not served here");
}

Expected<ClientMessageData, std::string> parseClientBinary(std::string_view bytes) {
  if (bytes.empty()) return unexpected("an empty binary message");
  if (bytes[0] != 1)
    return unexpected("binary opcode " + std::to_string(static_cast<uint8_t>(bytes[0])) +
                      " is not served here");
  if (bytes.size() < 5) return unexpected("a message data shorter than its channel id");
  uint32_t channel = 0;
  for (size_t i = 0; i < 4; ++i)
    channel |= static_cast<uint32_t>(static_cast<uint8_t>(bytes[1 + i])) << (8 * i);
  return ClientMessageData{channel, bytes.substr(5)};
}

}  // namespace wircam::recorder
