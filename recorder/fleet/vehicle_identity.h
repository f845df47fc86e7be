// Which vehicle a camera belongs to, by the device's own word: the name
// and serial number of its discovery answer (BCSA). A recorder given a
// device's address never discovered it, so it asks that address once (a
// BCSD sent to it alone) when the device is live; the answer names the
// vehicle in the fleet, whichever recorder sees it and whatever label a
// config gave it. Main loop only.
#pragma once

#include <glib.h>

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "common/socket.h"

namespace wircam::recorder {

struct VehicleIdentity {
  std::string name;
  std::string serial;
  bool operator==(const VehicleIdentity&) const = default;
};

// {"name", "serial"}, or null when unknown.
nlohmann::json toJson(const std::optional<VehicleIdentity>& vehicle);
std::optional<VehicleIdentity> vehicleOf(const nlohmann::json& json);

class VehicleIdentities {
 public:
  static constexpr auto kAnswerTimeoutMs = 2000;

  explicit VehicleIdentities(std::function<void(const std::string& device)> learnt)
      : learnt_(std::move(learnt)) {}
  ~VehicleIdentities();
  VehicleIdentities(const VehicleIdentities&) = delete;
  VehicleIdentities& operator=(const VehicleIdentities&) = delete;

  // Asks the device labelled `device` at host:port who it is, unless it
  // said so already or a question is out; `learnt` runs when it answers.
  // A device that does not answer is asked again at the next call.
  void ask(const std::string& device, const std::string& host, uint16_t port);
  std::optional<VehicleIdentity> of(const std::string& device) const;

 private:
  struct Question {
    VehicleIdentities* owner;
    std::string device;
    UniqueFd socket;
    guint watch = 0, timeout = 0;
  };
  static gboolean onAnswer(gint fd, GIOCondition, gpointer question);
  static gboolean onTimeout(gpointer question);

  std::function<void(const std::string& device)> learnt_;
  std::map<std::string, VehicleIdentity> known_;
  std::map<std::string, std::unique_ptr<Question>> asking_;
};

}  // namespace wircam::recorder
