#include "message_json.h"

#include <optional>

namespace wircam::wirc {

// Field names as in the structs; nlohmann's macros write both directions.
void to_json(nlohmann::json& j, const Version& v) {
  j = std::to_string(v.major) + "." + std::to_string(v.minor);
}
void from_json(const nlohmann::json& j, Version& v) {
  unsigned major = 0, minor = 0;
  if (std::sscanf(j.get<std::string>().c_str(), "%u.%u", &major, &minor) != 2 || major > 255 ||
      minor > 255)
    throw nlohmann::json::other_error::create(501, "a version is \"MAJOR.MINOR\"", &j);
  v = {static_cast<uint8_t>(major), static_cast<uint8_t>(minor)};
}
NLOHMANN_JSON_SERIALIZE_ENUM(AccessNotification,
                             {{AccessNotification::Granted, "granted"},
                              {AccessNotification::Denied, "denied"},
                              {AccessNotification::Revoked, "revoked"},
                              {AccessNotification::Notification, "notification"}})
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(Bcsd, system, version)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(Bcsa, hardware, software, name, serial)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(Tl, system, version, priority, name, statusPort)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(Dcfg, name, cameraOffMillivolts,
                                                deviceOffMillivolts)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(Ccfg, periods)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(Fcfg, values)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(Wst, connectionId, cameraCount, controlPort)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(Pcd, values)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(Psd, batteryMillivolts, analogMillivolts, inputs)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(Tlst, connectionId, priority, name)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(Areq, connectionId)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(Agr, connectionId, priority, name, notification)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(Fwup, md5)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(Stst, camera, port)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(Est, camera)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(Extout, destination, data)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(Err, command, code)
void to_json(nlohmann::json&, const Tlr&) {}
void from_json(const nlohmann::json&, Tlr&) {}
void to_json(nlohmann::json&, const Tlend&) {}
void from_json(const nlohmann::json&, Tlend&) {}
void to_json(nlohmann::json& j, const Wcfg& m) {
  j = {{"ssid", m.ssid},
       {"passwordLength", m.password.size()},
       {"accessPoint", m.accessPoint},
       {"secured", m.secured},
       {"channel", m.channel},
       {"country", m.country}};
}
void from_json(const nlohmann::json& j, Wcfg& m) {
  m.ssid = j.value("ssid", "");
  m.password = j.value("password", "");
  m.accessPoint = j.value("accessPoint", true);
  m.secured = j.value("secured", false);
  m.channel = j.value("channel", uint8_t{0});
  m.country = j.value("country", "");
}

}  // namespace wircam::wirc

namespace wircam::cli {

namespace {

// nlohmann converts a fraction to an integer field with a plain cast, which
// is undefined past the field's range: such input is refused before.
bool holdsAFraction(const nlohmann::json& json) {
  if (json.is_number_float()) return true;
  if (json.is_structured())
    for (const auto& item : json)
      if (holdsAFraction(item)) return true;
  return false;
}

// What is wrong with the input's fields, as the message written back shows
// them: a key that is no field of the message (a misspelt one would
// otherwise be left at its default), a field left out (no silent default
// either), or a value the field cannot hold (nlohmann wraps 300 into a
// uint8_t as 44). WCFG takes its password, which it writes back only as
// passwordLength.
std::optional<std::string> fieldProblem(const std::string& type, const nlohmann::json& input,
                                        const wirc::Message& message) {
  nlohmann::json written = std::visit([](const auto& m) { return nlohmann::json(m); }, message);
  if (!written.is_object()) written = nlohmann::json::object();
  bool isWcfg = std::holds_alternative<wirc::Wcfg>(message);
  std::string fields;
  for (const auto& [key, value] : written.items())
    if (!(isWcfg && key == "passwordLength")) fields += (fields.empty() ? "" : ", ") + key;
  if (isWcfg) fields += ", password";
  std::string known = " (" + type + "'s fields: " + (fields.empty() ? "none" : fields) + ")";
  for (const auto& [key, value] : input.items()) {
    if (key == "type" || (isWcfg && key == "password")) continue;
    if (!written.contains(key) || (isWcfg && key == "passwordLength"))
      return "\"" + key + "\" is no field of " + type + known;
    if (written[key] != value)
      return "\"" + key + "\": " + value.dump() + " does not fit the field";
  }
  for (const auto& [key, value] : written.items())
    if (!input.contains(key) && !(isWcfg && key == "passwordLength"))
      return type + " needs \"" + key + "\"" + known;
  return std::nullopt;
}

template <size_t I = 0>
Expected<wirc::Message, std::string> messageOfType(const std::string& type,
                                                   const nlohmann::json& json) {
  if constexpr (I == std::variant_size_v<wirc::Message>) {
    return unexpected("unknown message type '" + type + "'");
  } else {
    using T = std::variant_alternative_t<I, wirc::Message>;
    if (wirc::commandName(static_cast<uint8_t>(T::kCommand)) != type)
      return messageOfType<I + 1>(type, json);
    wirc::Message message{json.get<T>()};
    if (auto problem = fieldProblem(type, json, message)) return unexpected(*problem);
    return message;
  }
}

}  // namespace

nlohmann::json toJson(const wirc::Message& message) {
  nlohmann::json json = std::visit([](const auto& m) { return nlohmann::json(m); }, message);
  if (json.is_null()) json = nlohmann::json::object();
  json["type"] = wirc::commandName(wirc::commandCode(message));
  return json;
}

Expected<wirc::Message, std::string> fromJson(const nlohmann::json& json) {
  try {
    if (!json.is_object() || !json.contains("type"))
      return unexpected(std::string("each line needs a \"type\""));
    if (holdsAFraction(json)) return unexpected(std::string("numbers are whole numbers here"));
    return messageOfType(json.at("type").get<std::string>(), json);
  } catch (const nlohmann::json::exception& error) {
    return unexpected(std::string(error.what()));
  }
}

}  // namespace wircam::cli
