#include "fleet/drive_command.h"

#include <cmath>
#include <nlohmann/json.hpp>

namespace wircam::recorder {

namespace {

Expected<double, std::string> unitNumber(const nlohmann::json& message, const char* field) {
  auto it = message.find(field);
  if (it == message.end()) return unexpected(std::string("no '") + field + "'");
  if (!it->is_number()) return unexpected(std::string("'") + field + "' is not a number");
  double value = it->get<double>();
  if (!std::isfinite(value) || value < -1 || value > 1)
    return unexpected(std::string("'") + field + "' is outside -1..1");
  return value;
}

}  // namespace

Expected<DriveCommand, std::string> parseDriveCommand(std::string_view text) {
  if (text.size() > kMaxDriveMessage)
    return unexpected("longer than " + std::to_string(kMaxDriveMessage) + " bytes");
  auto message = nlohmann::json::parse(text, nullptr, false);
  if (message.is_discarded() || !message.is_object()) return unexpected("not a JSON object");
  DriveCommand command;
  auto seq = message.find("seq");
  if (seq != message.end()) {
    if (!seq->is_number_integer()) return unexpected("'seq' is not an integer");
    command.seq = seq->get<int64_t>();
  }
  auto steering = unitNumber(message, "steering");
  if (!steering) return unexpected(steering.error());
  auto throttle = unitNumber(message, "throttle");
  if (!throttle) return unexpected(throttle.error());
  command.steering = *steering;
  command.throttle = *throttle;
  return command;
}

std::string obeyDriveMessage(std::optional<std::string_view> text, const DriveFunction& drive) {
  auto command = text ? parseDriveCommand(*text)
                      : Expected<DriveCommand, std::string>(unexpected("not a text message"));
  if (!command) {
    // Whatever the page meant, the vehicle must not keep going on it.
    drive(0, 0);
    return nlohmann::json{{"error", command.error()}, {"neutral", true}}.dump();
  }
  auto obeyed = drive(command->steering, command->throttle);
  if (!obeyed) return nlohmann::json{{"error", "this camera's vehicle cannot be driven"}}.dump();
  return nlohmann::json{{"ack", command->seq}, {"obeyed", *obeyed}}.dump();
}

}  // namespace wircam::recorder
