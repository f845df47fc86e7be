#include "wirccontrol_settings.h"

#include "login_properties.h"
#include "property_table.h"

namespace wircam::gst::wirccontrol {

namespace {
PropertyTable<Settings> table;
}  // namespace

void installProperties(GObjectClass* gobject) {
  auto ready = static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS |
                                        GST_PARAM_MUTABLE_READY);
  auto live = static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS |
                                       GST_PARAM_MUTABLE_PLAYING | GST_PARAM_CONTROLLABLE);
  table.installOn(gobject);
  table.string(PROP_HOST, "host",
               "Address of the vehicle (for WiRC the same as wircsrc's: they share one "
               "login); empty = discover (WiRC) or probe the broadcast ports (BTEMP); RCOIP "
               "needs one",
               SETTING(host), ready);
  table.number(PROP_PORT, "port",
               "The vehicle's port: WiRC TCP control port, RCOIP receiver or BTEMP robot UDP "
               "port (0 = the protocol's default: 1984, 9048, 16980)",
               0, 65535, SETTING(port), ready);
  table.choice(PROP_PROTOCOL, "protocol",
               "What the vehicle speaks; the camera may be any video source",
               gst::vehicleProtocolType(), SETTING(protocol), ready);
  table.number(PROP_TARGET_ID, "target-id",
               "Id of the tag to follow (-1 = the largest tag in view)", -1, 65535,
               SETTING(targetId), live);
  table.number(PROP_STEERING_CHANNEL, "steering-channel",
               "PCD channel of the steering servo (1..8)", 1, 8, SETTING(steeringChannel), ready);
  table.number(PROP_THROTTLE_CHANNEL, "throttle-channel",
               "PCD channel of the motor controller (1..8)", 1, 8, SETTING(throttleChannel), ready);
  table.number(PROP_STEERING_KP, "steering-kp",
               "Steering PID: proportional gain (per radian of bearing)", 0, 100,
               SETTING(follow.steering.kp), live);
  table.number(PROP_STEERING_KI, "steering-ki", "Steering PID: integral gain", 0, 100,
               SETTING(follow.steering.ki), live);
  table.number(PROP_STEERING_KD, "steering-kd", "Steering PID: derivative gain", 0, 100,
               SETTING(follow.steering.kd), live);
  table.number(PROP_THROTTLE_KP, "throttle-kp",
               "Throttle PID: proportional gain (per metre of distance error)", 0, 100,
               SETTING(follow.throttle.kp), live);
  table.number(PROP_THROTTLE_KI, "throttle-ki", "Throttle PID: integral gain", 0, 100,
               SETTING(follow.throttle.ki), live);
  table.number(PROP_THROTTLE_KD, "throttle-kd", "Throttle PID: derivative gain", 0, 100,
               SETTING(follow.throttle.kd), live);
  table.number(PROP_TARGET_DISTANCE, "target-distance", "Distance to keep from the tag, metres",
               0.05, 100, SETTING(follow.targetDistance), live);
  table.number(PROP_TAG_SIZE, "tag-size",
               "Edge of the tag's black border, metres (distance from apparent size when "
               "apriltagdetect has no pose)",
               0.001, 100, SETTING(follow.tagSize), live);
  table.number(PROP_FX, "fx", "Camera focal length in pixels (0 = from horizontal-fov)", 0, 100000,
               SETTING(follow.fx), live);
  table.number(PROP_HORIZONTAL_FOV, "horizontal-fov", "Camera horizontal field of view, degrees", 1,
               179, SETTING(follow.horizontalFovDeg), live);
  table.number(PROP_NEUTRAL, "neutral", "Neutral pulse, µs (straight, stopped)", 800, 2200,
               SETTING(neutral), ready);
  table.number(PROP_MIN, "min", "Smallest pulse ever sent, µs", 800, 2200, SETTING(min), ready);
  table.number(PROP_MAX, "max", "Largest pulse ever sent, µs", 800, 2200, SETTING(max), ready);
  table.number(PROP_THROTTLE_DEADBAND, "throttle-deadband",
               "µs either side of neutral where the motor controller does not move: "
               "commands start beyond it",
               0, 500, SETTING(throttleDeadband), live);
  table.number(PROP_MAX_THROTTLE, "max-throttle",
               "Largest throttle command, 0..1 of the way to min/max", 0, 1, SETTING(maxThrottle),
               live);
  table.boolean(PROP_STEERING_REVERSED, "steering-reversed",
                "Servo mounted the other way: higher pulses steer right", SETTING(steeringReversed),
                live);
  table.boolean(PROP_THROTTLE_REVERSED, "throttle-reversed", "Higher pulses drive backwards",
                SETTING(throttleReversed), live);
  table.number(PROP_LOST_TIMEOUT, "lost-timeout",
               "Milliseconds without the target (or without any buffer) before both "
               "channels go to neutral",
               50, 10000, SETTING(lostTimeoutMs), ready);
  table.number(PROP_PCD_RATE, "pcd-rate",
               "Rate limit on changes: a changed command leaves at once unless another "
               "change left less than 1/pcd-rate s ago (keepalives do not count)",
               1, 1000, SETTING(pcdRate), ready);
  table.number(PROP_KEEPALIVE, "keepalive",
               "Milliseconds between repeats of an unchanged command; keep it well below "
               "the device's PCD timeout (200..2000 ms, 800 by default)",
               10, static_cast<double>(wirc::kMaxKeepalive.count()), SETTING(keepaliveMs), ready);
  table.boolean(PROP_ENABLED, "enabled", "Follow the tag; false = hold both channels at neutral",
                SETTING(enabled), live);
  table.boolean(PROP_TAKE_CONTROL, "take-control",
                "Ask the device for the control right (AREQ) at each login that does not "
                "bring it; the answer comes as a wirc-control-right message",
                SETTING(takeControl), ready);
  table.number(PROP_DRIVE_TIMEOUT, "drive-timeout",
               "Milliseconds a command by hand (the drive action) holds; without a newer "
               "one by then the vehicle goes to neutral (a dead-man)",
               20, 5000, SETTING(driveTimeoutMs), live);
  installLoginProperties(gobject, PROP_PERIODS, PROP_FAILSAFE);
}

bool setProperty(guint id, const GValue* value, Settings& settings) {
  return table.set(id, value, settings);
}

bool getProperty(guint id, const Settings& settings, GValue* value) {
  return table.get(id, settings, value);
}

vision::FollowConfig followConfig(const Settings& s) {
  vision::FollowConfig config = s.follow;
  auto map = [&](bool reversed, uint16_t deadband) {
    return vision::PulseMap{static_cast<uint16_t>(s.neutral), static_cast<uint16_t>(s.min),
                            static_cast<uint16_t>(s.max), reversed, deadband};
  };
  config.steeringMap = map(s.steeringReversed, 0);
  config.throttleMap = map(s.throttleReversed, static_cast<uint16_t>(s.throttleDeadband));
  config.throttle.outputMax = s.maxThrottle;
  config.throttle.outputMin = -s.maxThrottle;
  return config;
}

vision::FollowerSettings followerSettings(const Settings& s) {
  return {.targetId = s.targetId,
          .lostTimeout = std::chrono::milliseconds(s.lostTimeoutMs),
          .enabled = s.enabled};
}

link::Pulses neutralOf(const Settings& s) {
  link::Pulses pulses = link::neutralPulses();
  pulses[s.steeringChannel - 1] = static_cast<uint16_t>(s.neutral);
  pulses[s.throttleChannel - 1] = static_cast<uint16_t>(s.neutral);
  return pulses;
}

}  // namespace wircam::gst::wirccontrol
