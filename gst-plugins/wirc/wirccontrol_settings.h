// What a wirccontrol is set to: its properties (declared once, in a table),
// the settings they fill, and what the follower and the link make of them.
#pragma once

#include <gst/gst.h>

#include <set>
#include <string>

#include "control_link.h"
#include "target_follower.h"
#include "wirc/transmitter_session.h"

namespace wircam::gst::wirccontrol {

#define DEFAULT_HOST ""
#define DEFAULT_PORT 0
#define DEFAULT_PROTOCOL gst::VehicleProtocol::Wirc
#define DEFAULT_TARGET_ID -1
#define DEFAULT_STEERING_CHANNEL 1
#define DEFAULT_THROTTLE_CHANNEL 2
#define DEFAULT_NEUTRAL 1500
#define DEFAULT_MIN 1000
#define DEFAULT_MAX 2000
#define DEFAULT_THROTTLE_DEADBAND 50
#define DEFAULT_MAX_THROTTLE 0.8
#define DEFAULT_LOST_TIMEOUT 500
#define DEFAULT_PCD_RATE 50.0
#define DEFAULT_KEEPALIVE 100
#define DEFAULT_ENABLED true
#define DEFAULT_TAKE_CONTROL false
#define DEFAULT_DRIVE_TIMEOUT 250

enum Property : guint {
  PROP_0,
  PROP_HOST,
  PROP_PORT,
  PROP_PROTOCOL,
  PROP_TARGET_ID,
  PROP_STEERING_CHANNEL,
  PROP_THROTTLE_CHANNEL,
  PROP_STEERING_KP,
  PROP_STEERING_KI,
  PROP_STEERING_KD,
  PROP_THROTTLE_KP,
  PROP_THROTTLE_KI,
  PROP_THROTTLE_KD,
  PROP_TARGET_DISTANCE,
  PROP_TAG_SIZE,
  PROP_FX,
  PROP_HORIZONTAL_FOV,
  PROP_NEUTRAL,
  PROP_MIN,
  PROP_MAX,
  PROP_THROTTLE_DEADBAND,
  PROP_MAX_THROTTLE,
  PROP_STEERING_REVERSED,
  PROP_THROTTLE_REVERSED,
  PROP_LOST_TIMEOUT,
  PROP_PCD_RATE,
  PROP_KEEPALIVE,
  PROP_ENABLED,
  PROP_TAKE_CONTROL,
  PROP_DRIVE_TIMEOUT,
  PROP_HAS_CONTROL,
  PROP_PERIODS,
  PROP_FAILSAFE,
};

struct Settings {
  std::string host = DEFAULT_HOST;
  guint port = DEFAULT_PORT;
  gst::VehicleProtocol protocol = DEFAULT_PROTOCOL;
  gint targetId = DEFAULT_TARGET_ID;
  guint steeringChannel = DEFAULT_STEERING_CHANNEL;
  guint throttleChannel = DEFAULT_THROTTLE_CHANNEL;
  // Gains, camera and distance: the follower's own defaults.
  vision::FollowConfig follow;
  guint neutral = DEFAULT_NEUTRAL;
  guint min = DEFAULT_MIN;
  guint max = DEFAULT_MAX;
  guint throttleDeadband = DEFAULT_THROTTLE_DEADBAND;
  double maxThrottle = DEFAULT_MAX_THROTTLE;
  bool steeringReversed = false;
  bool throttleReversed = false;
  guint lostTimeoutMs = DEFAULT_LOST_TIMEOUT;
  double pcdRate = DEFAULT_PCD_RATE;
  guint keepaliveMs = DEFAULT_KEEPALIVE;
  bool keepaliveSet = false;
  bool enabled = DEFAULT_ENABLED;
  bool takeControl = DEFAULT_TAKE_CONTROL;
  guint driveTimeoutMs = DEFAULT_DRIVE_TIMEOUT;
  wirc::ChannelValues periods = wirc::SessionConfig{}.periods;
  wirc::ChannelValues failsafe = wirc::SessionConfig{}.failsafe;
  // The shared link's settings given: the pacing ones always (the element
  // is the link's one commander), the login ones when set.
  std::set<std::string> given = {"pcd-rate", "keepalive", "lost-timeout"};
};

// Installs every property but has-control (the element's own).
void installProperties(GObjectClass* gobject);

// Stores a table property's value; false for the others.
bool setProperty(guint id, const GValue* value, Settings& settings);
bool getProperty(guint id, const Settings& settings, GValue* value);

vision::FollowConfig followConfig(const Settings& s);
vision::FollowerSettings followerSettings(const Settings& s);
// Neutral on the element's two channels (the others are at 1500 anyway).
link::Pulses neutralOf(const Settings& s);

}  // namespace wircam::gst::wirccontrol
