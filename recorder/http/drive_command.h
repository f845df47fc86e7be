// A message of the drive mode's WebSocket, from the page:
//   {"seq": 12, "steering": -0.5, "throttle": 1}
// steering -1 (right) .. 1 (left), throttle -1 (reverse) .. 1 (ahead);
// seq is the page's, echoed in the answer so it can time the round trip.
#pragma once

#include <cstdint>
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

}  // namespace wircam::recorder
