// One client of the Foxglove WebSocket, without its socket: what it
// subscribed to, the channels it advertised to drive on, and what each of
// its messages asks of the server (http/foxglove_server.h does the I/O).
//
// A client drives a camera's vehicle by advertising /STREAM/drive (JSON)
// and publishing {"steering": S, "throttle": T}, or a Twist as Foxglove's
// Teleop panel sends it (linear.x the throttle, angular.z the steering),
// each in -1..1. Junk (not JSON, an unknown op or channel, a value out of
// range) closes the client: its vehicles go to neutral at once. Messages
// on a channel whose advertisement was refused (with a status) are dropped:
// a Teleop panel pointed at the wrong topic is told once, not cut off.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "foxglove/foxglove_protocol.h"

namespace wircam::recorder {

class FoxgloveSession {
 public:
  struct Server {
    std::function<bool(uint32_t channelId)> isChannel;
    std::function<bool(const std::string& camera)> isCamera;
    std::function<bool(const std::string& camera)> isDrivable;  // it steers a vehicle
    bool canDrive = false;  // with the access token only, as the web page's drive mode
  };
  struct Drive {
    std::string camera;
    double steering = 0, throttle = 0;
  };
  // What the server does for one message: send these status messages,
  // obey these drive commands (neutral ones among them), close the client
  // with `close` as the reason.
  struct Outcome {
    std::vector<std::string> replies;
    std::vector<Drive> drives;
    std::optional<std::string> close;
  };

  explicit FoxgloveSession(Server server) : server_(std::move(server)) {}

  Outcome text(std::string_view message);
  Outcome binary(std::string_view message);

  // The client's subscription to a channel, if any.
  std::optional<uint32_t> subscriptionTo(uint32_t channelId) const;
  // The channel is gone (its camera removed): so are subscriptions to it.
  void channelGone(uint32_t channelId);
  // The cameras this client drove: neutral for each when it goes.
  std::set<std::string> drivenCameras() const;

 private:
  void subscribe(const ClientSubscribe& message, Outcome& outcome);
  void advertise(const ClientAdvertise& message, Outcome& outcome);
  void unadvertise(const ClientUnadvertise& message, Outcome& outcome);

  Server server_;
  // Channel id -> the client's subscription id: looked up by channel for
  // every message sent (per frame), by id only when the client asks.
  std::map<uint32_t, uint32_t> subscriptions_;
  std::map<uint32_t, std::string> driveChannels_;  // the client's channel id -> camera
  std::set<uint32_t> refused_;  // channels it advertised and was told it cannot publish on
  std::set<std::string> driven_;
};

}  // namespace wircam::recorder
