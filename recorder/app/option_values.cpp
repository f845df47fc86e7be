// What one option's value means: numbers, sizes, addresses, devices,
// control URIs, follow tuning and position sources, each checked.
#include "app/option_values.h"

#include <glib.h>

#include <cmath>
#include <cstdlib>
#include <map>
#include <memory>

#include "marvelmind/position_client.h"

namespace wircam::recorder {

std::optional<double> number(const char* text) {
  char* end = nullptr;
  double value = std::strtod(text, &end);
  // NaN passes every range check and then casts to garbage: refused here.
  if (end == text || *end != '\0' || !std::isfinite(value)) return std::nullopt;
  return value;
}

std::optional<long long> wholeWithin(const char* text, double low, double high) {
  auto n = number(text);
  if (!n || *n < low || *n > high || *n != std::floor(*n)) return std::nullopt;
  return static_cast<long long>(*n);
}

std::optional<uint64_t> byteSize(const char* text) {
  char* end = nullptr;
  double value = std::strtod(text, &end);
  if (end == text || !std::isfinite(value) || value < 0) return std::nullopt;
  std::string unit = end;
  double scale = unit.empty()  ? 1
                 : unit == "K" ? 1e3
                 : unit == "M" ? 1e6
                 : unit == "G" ? 1e9
                 : unit == "T" ? 1e12
                               : 0;
  // Past 2^64 bytes the cast would be undefined, and no disk is that big.
  if (scale == 0 || value * scale >= 1.8e19) return std::nullopt;
  return static_cast<uint64_t>(value * scale);
}

std::optional<HostAndPort> hostAndPort(const std::string& text, int lowestPort) {
  auto colon = text.rfind(':');
  HostAndPort split{text.substr(0, colon), std::nullopt};
  if (colon == std::string::npos) return split;
  auto port = wholeWithin(text.substr(colon + 1).c_str(), lowestPort, 65535);
  if (!port) return std::nullopt;
  split.port = static_cast<uint16_t>(*port);
  return split;
}

std::optional<ServerAddress> parseServerAddress(const std::string& text) {
  auto split = hostAndPort(text, 0);  // port 0: any free one
  if (!split || !split->port) return std::nullopt;
  return ServerAddress{split->host, *split->port};
}

Expected<ControlTarget, std::string> parseControlTarget(const std::string& uri) {
  auto scheme = uri.find("://");
  ControlTarget target;
  target.protocol = uri.substr(0, scheme);
  if (scheme == std::string::npos ||
      (target.protocol != "wirc" && target.protocol != "rcoip" && target.protocol != "btemp"))
    return unexpected("control '" + uri + "' is not rcoip://HOST:PORT, btemp://HOST:PORT or " +
                      "wirc://HOST:PORT");
  auto address = hostAndPort(uri.substr(scheme + 3));
  if (!address) return unexpected("control '" + uri + "': a port is 1..65535");
  target.host = address->host;
  if (address->port) target.port = *address->port;
  if (target.host.empty() || target.host.find_first_of("/ \"'") != std::string::npos)
    return unexpected("control '" + uri + "' needs a host, as in rcoip://192.168.4.1:9048");
  return target;
}

Expected<DeviceTarget, std::string> deviceTarget(const std::string& argument) {
  DeviceTarget target;
  std::string text = argument.substr(0, argument.find(','));
  if (text.size() < argument.size()) {
    std::string extra = argument.substr(text.size() + 1);
    if (extra.rfind("control=", 0) != 0)
      return unexpected("--device " + argument + ": after the comma only control=URI");
    auto control = parseControlTarget(extra.substr(8));
    if (!control) return unexpected("--device " + argument + ": " + control.error());
    target.control = *control;
  }
  auto address = hostAndPort(text);
  if (!address) return unexpected("bad port in --device " + text + ": a port is 1..65535");
  target.host = address->host;
  if (address->port) target.port = *address->port;
  if (target.host.empty())
    return unexpected("--device needs a host, as in 192.168.1.1 or 127.0.0.1:1984");
  target.label = target.host + (target.port == 1984 ? "" : "-" + std::to_string(target.port));
  return target;
}

Expected<std::string, std::string> followTuning(const char* value) {
  static const std::map<std::string, std::pair<double, double>> kTunable = {
      {"steering-kp", {0, 100}},        {"steering-ki", {0, 100}}, {"steering-kd", {0, 100}},
      {"throttle-kp", {0, 100}},        {"throttle-ki", {0, 100}}, {"throttle-kd", {0, 100}},
      {"target-distance", {0.05, 100}}, {"max-throttle", {0, 1}}};
  auto decimal = [](double v) {
    char digits[G_ASCII_DTOSTR_BUF_SIZE];
    return std::string(g_ascii_dtostr(digits, sizeof digits, v));
  };
  std::string tuning;
  std::unique_ptr<gchar*, decltype(&g_strfreev)> pairs(g_strsplit(value, ",", -1), g_strfreev);
  for (gchar** pair = pairs.get(); *pair; ++pair) {
    std::string text = *pair;
    auto equals = text.find('=');
    auto range = kTunable.find(text.substr(0, equals));
    if (range == kTunable.end())
      return unexpected("'" + text.substr(0, equals) +
                        "' is not one of steering-kp, steering-ki, steering-kd, throttle-kp, "
                        "throttle-ki, throttle-kd, target-distance, max-throttle");
    auto given =
        equals == std::string::npos ? std::nullopt : number(text.substr(equals + 1).c_str());
    auto [low, high] = range->second;
    if (!given || *given < low || *given > high)
      return unexpected(range->first + " takes a number in " + decimal(low) + ".." + decimal(high));
    tuning += " " + range->first + "=" + decimal(*given);
  }
  return tuning;
}

Expected<std::optional<PositionSource>, std::string> positionSource(
    const std::optional<std::string>& dashboard, const std::optional<std::string>& beacons) {
  if (!dashboard && !beacons) return std::optional<PositionSource>();
  if (!dashboard)
    return unexpected(std::string("beacon= needs marvelmind=HOST[:PORT] (--marvelmind)"));
  if (!beacons)
    return unexpected("marvelmind " + *dashboard + " needs the vehicle's beacon (--beacon ADDR)");
  PositionSource source;
  auto address = hostAndPort(*dashboard);
  if (!address) return unexpected("marvelmind '" + *dashboard + "': a port is 1..65535");
  source.host = address->host;
  if (address->port) source.port = *address->port;
  if (source.host.empty() || source.host.find_first_of("/ \"'") != std::string::npos)
    return unexpected("marvelmind '" + *dashboard + "' needs a host, as in 192.168.1.50:49200");
  auto parsed = marvelmind::parseBeacons(*beacons);
  if (!parsed) return unexpected(parsed.error());
  for (uint8_t beacon : *parsed)
    source.beacons += (source.beacons.empty() ? "" : ",") + std::to_string(beacon);
  return std::optional<PositionSource>(source);
}

}  // namespace wircam::recorder
