#include "wircsrc_settings.h"

#include "login_properties.h"
#include "property_table.h"

namespace wircam::gst::wircsrc {

namespace {
PropertyTable<Settings> table;
}  // namespace

void installProperties(GObjectClass* gobject) {
  constexpr auto kReady = static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS |
                                                   GST_PARAM_MUTABLE_READY);
  constexpr auto kLive = static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS);
  table.installOn(gobject);
  table.string(PROP_HOST, "host",
               "Address of the WiRC device; empty = discover it on the local network (see "
               "device, discovery-address)",
               SETTING(host), kReady);
  table.number(PROP_PORT, "port", "TCP control / UDP discovery port of the device", 1, 65535,
               SETTING(port), kReady);
  table.string(PROP_DEVICE, "device",
               "When discovering: the device name or serial to pick (empty = the only one "
               "that answers)",
               SETTING(device), kReady);
  table.number(PROP_CAMERA, "camera", "Camera index on the device (0 .. its camera count - 1)", 0,
               255, SETTING(camera), kReady);
  table.number(PROP_STREAM_PORT, "stream-port", "Local UDP port for the video (0 = any free port)",
               0, 65535, SETTING(streamPort), kReady);
  table.string(PROP_TRANSMITTER_NAME, "transmitter-name",
               "Name this transmitter logs in with (up to 64 printable ASCII characters; "
               "shown in TLST; others are refused when set)",
               SETTING(transmitterName), kReady);
  table.number(PROP_PRIORITY, "priority",
               "Login priority: the highest may hand out the control right", 0, 255,
               SETTING(priority), kReady);
  table.number(PROP_FRAME_TIMEOUT, "frame-timeout",
               "Milliseconds an incomplete frame may wait for its missing packets before it "
               "is dropped",
               10, 10000, SETTING(frameTimeoutMs), kReady);
  table.boolean(PROP_RECONNECT, "reconnect",
                "Log in again (with backoff) after the connection is lost, and restart the "
                "stream",
                SETTING(reconnect), kReady);
  table.string(PROP_DISCOVERY_ADDRESS, "discovery-address",
               "Where BCSD is sent when host is empty (broadcast by default)",
               SETTING(discoveryAddress), kReady);
  table.number(PROP_LOGIN_TIMEOUT, "login-timeout",
               "Milliseconds to wait for discovery and login before failing", 100, 60000,
               SETTING(loginTimeoutMs), kReady);
  table.number(PROP_STATS_INTERVAL, "stats-interval",
               "Milliseconds between wirc-stats element messages (0 = none)", 0, 3600000,
               SETTING(statsIntervalMs), kLive);
  table.number(PROP_LINK_TIMEOUT, "link-timeout",
               "Milliseconds without a status report (PSD, every 500 ms) before the device "
               "counts as gone (power cut, out of range) and the link logs in again; 0 = "
               "never (at least 1000 otherwise)",
               0, 600000, SETTING(linkTimeoutMs), kReady);
  table.number(PROP_MAX_BAD_MESSAGES, "max-bad-messages",
               "Malformed messages one control connection may bring before the device "
               "counts as misbehaving: the connection is dropped and made again after a "
               "backoff",
               1, 1000000, SETTING(maxBadMessages), kReady);
  table.boolean(PROP_WAIT_FOR_DEVICE, "wait-for-device",
                "Keep trying to log in (with backoff) until the device appears, instead of "
                "failing after login-timeout; needs reconnect=true",
                SETTING(waitForDevice), kReady);
  installLoginProperties(gobject, PROP_PERIODS, PROP_FAILSAFE);
}

bool setProperty(guint id, const GValue* value, Settings& settings) {
  return table.set(id, value, settings);
}

bool getProperty(guint id, const Settings& settings, GValue* value) {
  return table.get(id, settings, value);
}

bool isLinkSetting(guint id) {
  return id == PROP_TRANSMITTER_NAME || id == PROP_PRIORITY || id == PROP_RECONNECT ||
         id == PROP_LOGIN_TIMEOUT || id == PROP_LINK_TIMEOUT || id == PROP_MAX_BAD_MESSAGES;
}

wirc::SessionConfig sessionConfig(const Settings& s) {
  return {.host = s.host,
          .port = static_cast<uint16_t>(s.port),
          .device = s.device,
          .discoveryAddress = s.discoveryAddress,
          .transmitterName = s.transmitterName,
          .priority = static_cast<uint8_t>(s.priority),
          .periods = s.periods,
          .failsafe = s.failsafe,
          .loginTimeout = std::chrono::milliseconds(s.loginTimeoutMs),
          .linkTimeout = std::chrono::milliseconds(s.linkTimeoutMs),
          .maxBadMessages = s.maxBadMessages,
          .reconnect = s.reconnect,
          .given = s.given};
}

}  // namespace wircam::gst::wircsrc
