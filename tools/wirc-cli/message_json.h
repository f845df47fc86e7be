// WiRC messages as JSON objects ({"type": "PCD", "values": [...]}), for
// `wirc-cli decode` / `encode` and for scripts that check the codec.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "common/expected.h"
#include "wirc/messages.h"

namespace wircam::cli {

// WCFG's password is never written out: only its length.
nlohmann::json toJson(const wirc::Message& message);
Expected<wirc::Message, std::string> fromJson(const nlohmann::json& json);

}  // namespace wircam::cli
