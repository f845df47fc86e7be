#include "fleet/vehicle_identity.h"

#include <glib-unix.h>

#include "log_line.h"
#include "wirc/discovery.h"

namespace wircam::recorder {

nlohmann::json toJson(const std::optional<VehicleIdentity>& vehicle) {
  if (!vehicle) return nullptr;
  return {{"name", vehicle->name}, {"serial", vehicle->serial}};
}

std::optional<VehicleIdentity> vehicleOf(const nlohmann::json& json) {
  if (!json.is_object()) return std::nullopt;
  auto name = json.find("name"), serial = json.find("serial");
  if (name == json.end() || serial == json.end() || !name->is_string() || !serial->is_string())
    return std::nullopt;
  return VehicleIdentity{*name, *serial};
}

VehicleIdentities::~VehicleIdentities() {
  for (auto& [device, question] : asking_) {
    g_source_remove(question->watch);
    g_source_remove(question->timeout);
  }
}

void VehicleIdentities::ask(const std::string& device, const std::string& host, uint16_t port) {
  if (host.empty() || known_.contains(device) || asking_.contains(device)) return;
  auto address = SocketAddress::resolve(host, port);
  if (!address) return;
  auto socket = wirc::sendDiscoveryRequest(*address);
  if (!socket) {
    logLine(device + ": cannot ask the device who it is: " + socket.error());
    return;
  }
  auto question = std::make_unique<Question>(Question{this, device, std::move(*socket)});
  question->watch = g_unix_fd_add(question->socket.get(), G_IO_IN, onAnswer, question.get());
  question->timeout = g_timeout_add(kAnswerTimeoutMs, onTimeout, question.get());
  asking_[device] = std::move(question);
}

std::optional<VehicleIdentity> VehicleIdentities::of(const std::string& device) const {
  auto found = known_.find(device);
  if (found == known_.end()) return std::nullopt;
  return found->second;
}

gboolean VehicleIdentities::onAnswer(gint fd, GIOCondition, gpointer data) {
  auto* question = static_cast<Question*>(data);
  auto answer = wirc::readDiscoveryAnswer(fd);
  if (!answer) return G_SOURCE_CONTINUE;  // not a BCSA: the next datagram may be
  auto* owner = question->owner;
  std::string device = question->device;
  owner->known_[device] = {answer->advertisement.name, answer->advertisement.serial};
  logLine(device + ": vehicle " + printableText(answer->advertisement.name) + ", serial " +
          printableText(answer->advertisement.serial));
  g_source_remove(question->timeout);
  question->watch = question->timeout = 0;
  owner->asking_.erase(device);  // the watch returns G_SOURCE_REMOVE below
  owner->learnt_(device);
  return G_SOURCE_REMOVE;
}

gboolean VehicleIdentities::onTimeout(gpointer data) {
  auto* question = static_cast<Question*>(data);
  g_source_remove(question->watch);
  question->watch = question->timeout = 0;
  std::string device = question->device;
  question->owner->asking_.erase(device);  // no answer: asked again when next live
  return G_SOURCE_REMOVE;
}

}  // namespace wircam::recorder
