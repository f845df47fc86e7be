// What a wircsrc is set to: its properties (declared once, in a table),
// the settings they fill, and the shared link's configuration they make.
#pragma once

#include <gst/gst.h>

#include <set>
#include <string>

#include "wirc/transmitter_session.h"

namespace wircam::gst::wircsrc {

#define DEFAULT_HOST ""
#define DEFAULT_PORT 1984
#define DEFAULT_DEVICE ""
#define DEFAULT_CAMERA 0
#define DEFAULT_STREAM_PORT 0
#define DEFAULT_TRANSMITTER_NAME "wircam"
#define DEFAULT_PRIORITY 0
#define DEFAULT_FRAME_TIMEOUT 200
#define DEFAULT_RECONNECT true
#define DEFAULT_DISCOVERY_ADDRESS "255.255.255.255"
#define DEFAULT_LOGIN_TIMEOUT 3000
#define DEFAULT_STATS_INTERVAL 1000
#define DEFAULT_LINK_TIMEOUT 2000
#define DEFAULT_MAX_BAD_MESSAGES 100
#define DEFAULT_WAIT_FOR_DEVICE false

enum Property : guint {
  PROP_0,
  PROP_HOST,
  PROP_PORT,
  PROP_DEVICE,
  PROP_CAMERA,
  PROP_STREAM_PORT,
  PROP_TRANSMITTER_NAME,
  PROP_PRIORITY,
  PROP_FRAME_TIMEOUT,
  PROP_RECONNECT,
  PROP_DISCOVERY_ADDRESS,
  PROP_LOGIN_TIMEOUT,
  PROP_STATS_INTERVAL,
  PROP_STATS,
  PROP_LINK_TIMEOUT,
  PROP_MAX_BAD_MESSAGES,
  PROP_PERIODS,
  PROP_FAILSAFE,
  PROP_WAIT_FOR_DEVICE,
};

struct Settings {
  std::string host = DEFAULT_HOST;
  guint port = DEFAULT_PORT;
  std::string device = DEFAULT_DEVICE;
  guint camera = DEFAULT_CAMERA;
  guint streamPort = DEFAULT_STREAM_PORT;
  std::string transmitterName = DEFAULT_TRANSMITTER_NAME;
  guint priority = DEFAULT_PRIORITY;
  guint frameTimeoutMs = DEFAULT_FRAME_TIMEOUT;
  bool reconnect = DEFAULT_RECONNECT;
  std::string discoveryAddress = DEFAULT_DISCOVERY_ADDRESS;
  guint loginTimeoutMs = DEFAULT_LOGIN_TIMEOUT;
  guint statsIntervalMs = DEFAULT_STATS_INTERVAL;
  guint linkTimeoutMs = DEFAULT_LINK_TIMEOUT;
  guint maxBadMessages = DEFAULT_MAX_BAD_MESSAGES;
  bool waitForDevice = DEFAULT_WAIT_FOR_DEVICE;
  wirc::ChannelValues periods = wirc::SessionConfig{}.periods;
  wirc::ChannelValues failsafe = wirc::SessionConfig{}.failsafe;
  std::set<std::string> given;  // the shared link's settings the user set
};

// Installs every property but `stats` (the element's own).
void installProperties(GObjectClass* gobject);

// Stores a table property's value; false for the others.
bool setProperty(guint id, const GValue* value, Settings& settings);
bool getProperty(guint id, const Settings& settings, GValue* value);

// The shared link's settings: a user's value counts as given (see `given`).
bool isLinkSetting(guint id);

wirc::SessionConfig sessionConfig(const Settings& s);

}  // namespace wircam::gst::wircsrc
