#include "fleet/mqtt_url.h"

#include <cctype>
#include <cstdlib>

namespace wircam::recorder {

namespace {

// Percent escapes in the user name and password ("%40" for "@").
std::string unescape(const std::string& text) {
  std::string out;
  for (size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '%' && i + 2 < text.size() &&
        std::isxdigit(static_cast<unsigned char>(text[i + 1])) &&
        std::isxdigit(static_cast<unsigned char>(text[i + 2]))) {
      out += static_cast<char>(std::strtol(text.substr(i + 1, 2).c_str(), nullptr, 16));
      i += 2;
    } else {
      out += text[i];
    }
  }
  return out;
}

}  // namespace

Expected<MqttUrl, std::string> parseMqttUrl(const std::string& text) {
  const std::string plain = "mqtt://", secure = "mqtts://";
  MqttUrl url;
  url.tls = text.rfind(secure, 0) == 0;
  if (!url.tls && text.rfind(plain, 0) != 0)
    return unexpected("'" + text + "' is not mqtt://[user:pass@]HOST[:PORT] (or mqtts://)");
  if (url.tls) url.port = 8883;
  std::string rest = text.substr((url.tls ? secure : plain).size());
  if (auto at = rest.rfind('@'); at != std::string::npos) {
    std::string credentials = rest.substr(0, at);
    rest = rest.substr(at + 1);
    auto colon = credentials.find(':');
    url.user = unescape(credentials.substr(0, colon));
    if (colon != std::string::npos) url.password = unescape(credentials.substr(colon + 1));
  }
  if (!rest.empty() && rest.back() == '/') rest.pop_back();
  auto colon = rest.rfind(':');
  url.host = rest.substr(0, colon);
  if (colon != std::string::npos) {
    char* end = nullptr;
    long port = std::strtol(rest.c_str() + colon + 1, &end, 10);
    if (*end != '\0' || port < 1 || port > 65535)
      return unexpected("'" + text + "': a port is 1..65535");
    url.port = static_cast<uint16_t>(port);
  }
  if (url.host.empty() || url.host.find_first_of("/ ") != std::string::npos)
    return unexpected("'" + text + "' needs a host, as in mqtt://192.168.1.10:1883");
  return url;
}

}  // namespace wircam::recorder
