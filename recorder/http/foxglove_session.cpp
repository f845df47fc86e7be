#include "http/foxglove_session.h"

#include <algorithm>
#include <nlohmann/json.hpp>

#include "fleet/drive_command.h"

namespace wircam::recorder {

namespace {

constexpr std::string_view kDriveSuffix = "/drive";

// "/STREAM/drive" -> STREAM
std::optional<std::string> cameraOfDriveTopic(const std::string& topic) {
  if (topic.size() <= kDriveSuffix.size() + 1 || topic[0] != '/' || !topic.ends_with(kDriveSuffix))
    return std::nullopt;
  return topic.substr(1, topic.size() - 1 - kDriveSuffix.size());
}

// {"steering", "throttle"}, or a Twist: angular.z steers (positive: left,
// as a turn counter-clockwise), linear.x drives (positive: ahead).
Expected<DriveCommand, std::string> driveIn(std::string_view payload) {
  if (payload.size() > kMaxDriveMessage)
    return unexpected("a drive message longer than " + std::to_string(kMaxDriveMessage) + " bytes");
  auto message = nlohmann::json::parse(payload, nullptr, false);
  if (message.is_object() && message.contains("linear") && message.contains("angular")) {
    const auto& linear = message["linear"];
    const auto& angular = message["angular"];
    if (!linear.is_object() || !angular.is_object())
      return unexpected("a Twist's linear and angular are objects");
    nlohmann::json asDrive = {{"steering", angular.value("z", nlohmann::json())},
                              {"throttle", linear.value("x", nlohmann::json())}};
    auto command = parseDriveCommand(asDrive.dump());
    if (!command) {
      // Named as the Twist names them.
      std::string why = command.error();
      for (auto [ours, theirs] : {std::pair("'steering'", "angular.z"), {"'throttle'", "linear.x"}})
        if (auto at = why.find(ours); at != std::string::npos)
          why.replace(at, std::string_view(ours).size(), theirs);
      return unexpected("a Twist's " + why);
    }
    return command;
  }
  return parseDriveCommand(payload);
}

}  // namespace

FoxgloveSession::Outcome FoxgloveSession::text(std::string_view text) {
  Outcome outcome;
  auto message = parseClientText(text);
  if (!message) {
    outcome.close = message.error();
  } else if (auto* subscription = std::get_if<ClientSubscribe>(&*message)) {
    subscribe(*subscription, outcome);
  } else if (auto* unsubscription = std::get_if<ClientUnsubscribe>(&*message)) {
    for (uint32_t id : unsubscription->subscriptionIds)
      if (!std::erase_if(subscriptions_, [&](const auto& s) { return s.second == id; }))
        outcome.replies.push_back(statusMessage(
            FoxgloveStatusLevel::Warning, "no subscription " + std::to_string(id) + " to end"));
  } else if (auto* advertisement = std::get_if<ClientAdvertise>(&*message)) {
    advertise(*advertisement, outcome);
  } else {
    unadvertise(std::get<ClientUnadvertise>(*message), outcome);
  }
  if (outcome.close)
    for (const auto& camera : drivenCameras()) outcome.drives.push_back({camera, 0, 0});
  return outcome;
}

void FoxgloveSession::subscribe(const ClientSubscribe& message, Outcome& outcome) {
  for (auto subscription : message.subscriptions) {
    // Named, not bound: clang 14 lets no lambda capture a structured binding.
    uint32_t id = subscription.first, channel = subscription.second;
    bool idInUse = std::any_of(subscriptions_.begin(), subscriptions_.end(),
                               [&](const auto& s) { return s.second == id; });
    if (idInUse) {
      outcome.replies.push_back(statusMessage(
          FoxgloveStatusLevel::Error, "subscription id " + std::to_string(id) + " is in use"));
    } else if (!server_.isChannel(channel)) {
      outcome.replies.push_back(
          statusMessage(FoxgloveStatusLevel::Warning,
                        "channel " + std::to_string(channel) + " is not advertised"));
    } else if (subscriptionTo(channel)) {
      outcome.replies.push_back(
          statusMessage(FoxgloveStatusLevel::Warning,
                        "already subscribed to channel " + std::to_string(channel)));
    } else {
      subscriptions_[channel] = id;
    }
  }
}

void FoxgloveSession::advertise(const ClientAdvertise& message, Outcome& outcome) {
  for (const auto& channel : message.channels) {
    auto camera = cameraOfDriveTopic(channel.topic);
    std::string refusal;
    if (!server_.canDrive)
      refusal = "driving needs the recorder started with --http-token (given to this connection)";
    else if (!camera || !server_.isCamera(*camera))
      refusal = "only /STREAM/drive is published here, STREAM a camera; not '" +
                channel.topic.substr(0, 80) + "'";
    else if (!server_.isDrivable(*camera))
      refusal = *camera +
                "'s vehicle cannot be driven: the recorder steers a camera's vehicle with --follow";
    else if (channel.encoding != "json")
      refusal = channel.topic + " takes JSON, not '" + channel.encoding.substr(0, 40) + "'";
    else if (driveChannels_.contains(channel.id))
      refusal = "client channel id " + std::to_string(channel.id) + " is in use";
    if (!refusal.empty()) {
      outcome.replies.push_back(statusMessage(FoxgloveStatusLevel::Error, refusal));
      refused_.insert(channel.id);
      continue;
    }
    refused_.erase(channel.id);
    driveChannels_[channel.id] = *camera;
  }
}

void FoxgloveSession::unadvertise(const ClientUnadvertise& message, Outcome& outcome) {
  for (uint32_t id : message.channelIds) {
    refused_.erase(id);
    auto it = driveChannels_.find(id);
    if (it == driveChannels_.end()) continue;
    std::string camera = it->second;
    driveChannels_.erase(it);
    // Its publisher is gone: the vehicle is not left on its last command.
    bool stillDriven = std::any_of(driveChannels_.begin(), driveChannels_.end(),
                                   [&](const auto& c) { return c.second == camera; });
    if (!stillDriven && driven_.erase(camera)) outcome.drives.push_back({camera, 0, 0});
  }
}

FoxgloveSession::Outcome FoxgloveSession::binary(std::string_view bytes) {
  Outcome outcome;
  auto message = parseClientBinary(bytes);
  if (!message) {
    outcome.close = message.error();
  } else if (refused_.contains(message->channelId)) {
    // Told so when it advertised the channel: dropped.
  } else if (auto it = driveChannels_.find(message->channelId); it == driveChannels_.end()) {
    outcome.close = "a message on channel " + std::to_string(message->channelId) +
                    ", which this client did not advertise";
  } else if (auto command = driveIn(message->payload); !command) {
    outcome.close = it->second + "/drive: " + command.error();
  } else {
    driven_.insert(it->second);
    outcome.drives.push_back({it->second, command->steering, command->throttle});
  }
  if (outcome.close)
    for (const auto& camera : drivenCameras()) outcome.drives.push_back({camera, 0, 0});
  return outcome;
}

std::optional<uint32_t> FoxgloveSession::subscriptionTo(uint32_t channelId) const {
  auto it = subscriptions_.find(channelId);
  if (it == subscriptions_.end()) return std::nullopt;
  return it->second;
}

void FoxgloveSession::channelGone(uint32_t channelId) { subscriptions_.erase(channelId); }

std::set<std::string> FoxgloveSession::drivenCameras() const {
  // A camera whose drive channel was advertised is neutralised too, even
  // before its first command: the client may have meant to stop it.
  std::set<std::string> cameras = driven_;
  for (const auto& [id, camera] : driveChannels_) cameras.insert(camera);
  return cameras;
}

}  // namespace wircam::recorder
