// A message of the drive mode's WebSocket, from the page:
//   {"seq": 12, "steering": -0.5, "throttle": 1}
// steering -1 (right) .. 1 (left), throttle -1 (reverse) .. 1 (ahead);
// seq is the page's, echoed in the answer so it can time the round trip.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

#include "common/expected.h"

namespace wircam::recorder {

struct DriveCommand {
  int64_t seq = 0;
  double steering = 0;
  double throttle = 0;
};

// Kept small: a page sends a few dozen bytes.
constexpr size_t kMaxDriveMessage = 256;

// The command, or why the message is refused (then the vehicle goes to
// neutral): not JSON, not an object, a field missing or not a finite
// number within -1..1, too long.
Expected<DriveCommand, std::string> parseDriveCommand(std::string_view text);

// Drives one camera's vehicle: whether it obeys (nullopt: it cannot be driven).
using DriveFunction = std::function<std::optional<bool>(double steering, double throttle)>;

// One message of a drive channel (the WebSocket or WebRTC's data channel;
// nullopt: a binary one), obeyed: the reply, {"ack": seq, "obeyed": bool},
// or {"error": ...} — with "neutral": true when the message was refused, as
// the vehicle was then sent neutral.
std::string obeyDriveMessage(std::optional<std::string_view> text, const DriveFunction& drive);

}  // namespace wircam::recorder
