// A camera's event (the JSON the supervisor hears: link changes, states,
// closed segments, stale positions, hook failures) as one line of text, for
// the log channel of a Foxglove client.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

namespace wircam::recorder {

std::string eventText(const nlohmann::json& event);

}  // namespace wircam::recorder
