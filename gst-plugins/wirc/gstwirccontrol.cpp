// clang-format off
/**
 * SECTION:element-wirccontrol
 *
 * Visual servoing: reads the WircTagMeta that apriltagdetect attached to each
 * passing buffer and turns the target tag's bearing and distance into
 * steering and throttle pulses (PID per axis, deadband, slew-rate limit,
 * pulse limits). The device's shared link sends a command the moment it
 * changes (at most `pcd-rate` changes per second) and repeats it every `keepalive`
 * ms otherwise, so the device's watchdog stays fed. Buffers pass through
 * untouched, so it can sit before a tee.
 *
 * Safety: when the target has not been seen for `lost-timeout`, or
 * `enabled` is false, both channels go to `neutral`; when no buffer comes at
 * all (a stalled pipeline) the link falls back to the failsafe after the
 * same time, and keeps the link up; every pulse stays inside `min`..`max`
 * and 800..2200 µs. A `wirc-control` element message reports each command.
 *
 * The control right: only the transmitter holding it steers. `has-control`
 * says whether this one does; a `wirc-control-right` message reports each
 * change (`has-control`, `holder`) and the answer to a request (`request`:
 * granted or denied, `reason`). Steering without the right posts a warning
 * once. The `request-control` action signal (or `take-control=true`, at each
 * login) asks the device for it with AREQ.
 *
 * Driving by hand: the `drive` action signal (steering, throttle in -1..1)
 * sends a command at once, within the same limits, and holds it for
 * `drive-timeout` ms (250 by default) while the follower keeps off; without
 * a newer one by then the vehicle goes to neutral, frames or not. Each is
 * posted as a `wirc-drive` element message (`reason`: command, dead-man);
 * while one holds, each frame's `wirc-control` message says `manual` and
 * carries the command by hand (what the vehicle is sent), not the
 * follower's.
 *
 * The vehicle may speak WiRC, RCOIP or BTEMP (`protocol`), whatever the
 * video comes from: the same follower, limits and failsafe steer all three.
 * RCOIP sends channels 1..8 as bytes (800..2200 µs → 0..255) to a receiver
 * that has no control right to give; BTEMP registers with the robot (the
 * control right) and sends channels 1..4 as Throt1..4 in CTRL every
 * `keepalive` ms. Status reports (battery, RSSI, pins) and link changes are
 * posted as `wirc-vehicle` element messages; a link already live when the
 * element starts is posted then.
 *
 * ## Example launch lines
 * |[
 * gst-launch-1.0 wircsrc host=127.0.0.1 ! tjpegdec ! apriltagdetect quad-decimate=1 ! wirccontrol host=127.0.0.1 target-id=0 target-distance=1.0 ! fakesink
 * ]|
 * |[
 * gst-launch-1.0 v4l2src ! videoconvert ! apriltagdetect ! wirccontrol protocol=rcoip host=192.168.4.1 port=9048 ! fakesink
 * ]|
 */
// clang-format on
#include "gstwirccontrol.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "control_link.h"
#include "gst_scoped.h"
#include "login_properties.h"
#include "manual_drive.h"
#include "target_follower.h"
#include "wirc/transmitter_session.h"
#include "wirc_bus_messages.h"
#include "wirc_tag_meta.h"
#include "wirccontrol_settings.h"

GST_DEBUG_CATEGORY_STATIC(wirc_control_debug);
#define GST_CAT_DEFAULT wirc_control_debug

namespace {

using namespace wircam;
using namespace wircam::gst::wirccontrol;

enum { SIGNAL_REQUEST_CONTROL, SIGNAL_DRIVE, SIGNAL_COUNT };
guint signals[SIGNAL_COUNT];
GParamSpec* hasControlSpec;

struct WircControlState {
  Settings settings;  // guarded by the object lock
  bool settingsChanged = true;

  // Streaming thread only.
  Settings active;  // the settings in use, refreshed when one changes
  std::optional<vision::TargetFollower> follower;
  vision::TargetFollower::Clock::time_point lastStep;  // the last buffer's running time
  std::vector<vision::TagSighting> sightings;          // reused per frame
  bool warnedWithoutControl = false;

  // Set in start(), cleared in stop(); the link's listener runs on the event loop.
  std::shared_ptr<link::VehicleLink> session;
  int sessionListener = 0;
  std::atomic<bool> hasControl{false};
  // Commands by hand (the `drive` action); created in init().
  std::unique_ptr<gst::ManualDrive> manual;
  // The last of them, for the per-frame control message while it holds:
  // that message says what the vehicle is sent, not what the follower
  // (kept off meanwhile) would send.
  std::mutex manualMutex;
  double manualSteering = 0, manualThrottle = 0;
  guint manualSteeringPulse = 0, manualThrottlePulse = 0;
};

double meanEdge(const WircTag& tag) {
  double total = 0;
  for (int i = 0; i < 4; ++i) {
    int j = (i + 1) % 4;
    total += std::hypot(tag.corners[2 * j] - tag.corners[2 * i],
                        tag.corners[2 * j + 1] - tag.corners[2 * i + 1]);
  }
  return total / 4;
}

void readSightings(WircTagMeta* meta, std::vector<vision::TagSighting>& out) {
  out.clear();
  if (!meta) return;
  for (guint i = 0; i < meta->tags->len; ++i) {
    const auto& tag = g_array_index(meta->tags, WircTag, i);
    out.push_back({tag.id, tag.cx, meanEdge(tag),
                   tag.has_pose ? std::optional<double>(tag.z) : std::nullopt});
  }
}

}  // namespace

struct _GstWircControl {
  GstBaseTransform parent;
  WircControlState* state;
};

G_DEFINE_TYPE(GstWircControl, gst_wirc_control, GST_TYPE_BASE_TRANSFORM)

static GstStaticPadTemplate sink_template =
    GST_STATIC_PAD_TEMPLATE("sink", GST_PAD_SINK, GST_PAD_ALWAYS, GST_STATIC_CAPS_ANY);
static GstStaticPadTemplate src_template =
    GST_STATIC_PAD_TEMPLATE("src", GST_PAD_SRC, GST_PAD_ALWAYS, GST_STATIC_CAPS_ANY);

static void post_control_right(GstWircControl* self, GstStructure* s) {
  gst_element_post_message(GST_ELEMENT(self), gst_message_new_element(GST_OBJECT(self), s));
}

// On the event loop: the control right and the answers to AREQ.
static void on_link_event(GstWircControl* self, const link::LinkEvent& event) {
  auto* state = self->state;
  GST_DEBUG_OBJECT(self, "link: %s", link::describe(event).c_str());
  if (const auto* right = std::get_if<link::ControlRightChanged>(&event)) {
    bool had = state->hasControl.exchange(right->hasControl);
    GST_INFO_OBJECT(self, "%s", link::describe(event).c_str());
    post_control_right(self, gst_structure_new(wircam::bus::ControlRight::kName, "has-control",
                                               G_TYPE_BOOLEAN, right->hasControl, "holder",
                                               G_TYPE_STRING, right->holder.c_str(), nullptr));
    if (had != right->hasControl) g_object_notify_by_pspec(G_OBJECT(self), hasControlSpec);
  } else if (const auto* answer = std::get_if<link::ControlRequestAnswered>(&event)) {
    GST_INFO_OBJECT(self, "%s", link::describe(event).c_str());
    post_control_right(
        self, gst_structure_new(wircam::bus::ControlRight::kName, "has-control", G_TYPE_BOOLEAN,
                                state->hasControl.load(), "request", G_TYPE_STRING,
                                answer->granted ? "granted" : "denied", "reason", G_TYPE_STRING,
                                answer->reason.c_str(), nullptr));
  } else if (const auto* report = std::get_if<link::TelemetryReceived>(&event)) {
    gst_element_post_message(
        GST_ELEMENT(self),
        gst_message_new_element(GST_OBJECT(self), gst::vehicleStatusStructure(report->telemetry)));
  } else if (const auto* changed = std::get_if<link::StateChanged>(&event)) {
    // The vehicle's link, for the application and the recorder's telemetry.
    gst_element_post_message(
        GST_ELEMENT(self),
        gst_message_new_element(
            GST_OBJECT(self),
            gst_structure_new(wircam::bus::Vehicle::kName, "event", G_TYPE_STRING,
                              link::describe(event).c_str(), "state", G_TYPE_STRING,
                              link::linkStateName(changed->state), nullptr)));
    std::shared_ptr<link::VehicleLink> session;
    {
      gst::GLibLocker lock(self);
      if (state->settings.takeControl) session = state->session;
    }
    if (session && changed->state == link::LinkState::Live && !state->hasControl)
      session->requestControl();
  }
}

static void gst_wirc_control_request_control(GstWircControl* self) {
  std::shared_ptr<link::VehicleLink> session;
  {
    gst::GLibLocker lock(self);
    session = self->state->session;
  }
  if (!session) {
    GST_WARNING_OBJECT(self, "request-control before the element started: nothing to ask");
    return;
  }
  session->requestControl();
}

static void post_drive(GstWircControl* self, const char* reason, const link::Pulses& pulses,
                       guint steeringChannel, guint throttleChannel) {
  gst_element_post_message(
      GST_ELEMENT(self),
      gst_message_new_element(
          GST_OBJECT(self),
          gst_structure_new(
              wircam::bus::Drive::kName, "reason", G_TYPE_STRING, reason, "steering-pulse",
              G_TYPE_UINT, static_cast<guint>(pulses[steeringChannel - 1]), "throttle-pulse",
              G_TYPE_UINT, static_cast<guint>(pulses[throttleChannel - 1]), "has-control",
              G_TYPE_BOOLEAN, self->state->hasControl.load(), nullptr)));
}

static gboolean gst_wirc_control_drive(GstWircControl* self, gdouble steering, gdouble throttle) {
  auto* state = self->state;
  std::shared_ptr<link::VehicleLink> session;
  Settings settings;
  {
    gst::GLibLocker lock(self);
    session = state->session;
    settings = state->settings;
  }
  if (!session) {
    GST_WARNING_OBJECT(self, "drive before the element started: no vehicle to drive");
    return FALSE;
  }
  link::Pulses neutral = neutralOf(settings);
  link::Pulses pulses = neutral;
  const char* reason = "command";
  if (std::isfinite(steering) && std::isfinite(throttle)) {
    auto config = followConfig(settings);
    pulses[settings.steeringChannel - 1] = config.steeringMap.toPulse(steering);
    pulses[settings.throttleChannel - 1] =
        config.throttleMap.toPulse(std::clamp(throttle, -1.0, 1.0) * settings.maxThrottle);
  } else {
    GST_WARNING_OBJECT(self, "drive: steering and throttle must be numbers; neutral sent");
    reason = "not a number: neutral";
  }
  {
    std::lock_guard lock(state->manualMutex);
    bool sent = reason == std::string_view("command");
    state->manualSteering = sent ? steering : 0;
    state->manualThrottle = sent ? std::clamp(throttle, -1.0, 1.0) * settings.maxThrottle : 0;
    state->manualSteeringPulse = pulses[settings.steeringChannel - 1];
    state->manualThrottlePulse = pulses[settings.throttleChannel - 1];
  }
  state->manual->drive(session, pulses, neutral,
                       std::chrono::milliseconds(settings.driveTimeoutMs));
  post_drive(self, reason, pulses, settings.steeringChannel, settings.throttleChannel);
  return state->hasControl.load();
}

static gboolean gst_wirc_control_start(GstBaseTransform* transform) {
  auto* self = GST_WIRC_CONTROL(transform);
  auto* state = self->state;
  Settings settings;
  {
    gst::GLibLocker lock(self);
    settings = state->settings;
  }
  if (settings.protocol == gst::VehicleProtocol::Btemp &&
      std::max(settings.steeringChannel, settings.throttleChannel) > 4) {
    GST_ELEMENT_ERROR(self, LIBRARY, SETTINGS,
                      ("BTEMP carries channels 1..4 only (Throt1..Throt4)"),
                      ("Set steering-channel and throttle-channel within 1..4."));
    return FALSE;
  }
  if (settings.steeringChannel == settings.throttleChannel) {
    GST_ELEMENT_ERROR(
        self, LIBRARY, SETTINGS,
        ("steering-channel and throttle-channel are both %u", settings.steeringChannel),
        ("Give them two different channels of 1..8."));
    return FALSE;
  }
  if (settings.min > settings.neutral || settings.neutral > settings.max) {
    GST_ELEMENT_ERROR(self, LIBRARY, SETTINGS, ("Pulse limits out of order"),
                      ("Need min <= neutral <= max (now %u, %u, %u).", settings.min,
                       settings.neutral, settings.max));
    return FALSE;
  }
  // The commander's pacing settings are the link's; another element that
  // gave different ones is named in the error.
  auto session =
      gst::acquireControlLink({.protocol = settings.protocol,
                               .host = settings.host,
                               .port = static_cast<uint16_t>(settings.port),
                               .rateLimit = settings.pcdRate,
                               .keepalive = std::chrono::milliseconds(settings.keepaliveMs),
                               .keepaliveGiven = settings.keepaliveSet,
                               .commandTtl = std::chrono::milliseconds(settings.lostTimeoutMs),
                               .periods = settings.periods,
                               .failsafe = settings.failsafe,
                               .given = settings.given},
                              GST_OBJECT_NAME(self));
  if (!session) {
    GST_ELEMENT_ERROR(self, RESOURCE, SETTINGS,
                      ("Cannot use the %s vehicle's link", gst::protocolName(settings.protocol)),
                      ("%s", session.error().c_str()));
    return FALSE;
  }
  state->hasControl = (*session)->status().hasControl;
  state->warnedWithoutControl = false;
  state->follower.reset();
  // A link already live (another element's, or a receiver that answered
  // at once) is heard from addListener() itself: the application sees its
  // state either way.
  state->sessionListener =
      (*session)->addListener([self](const link::LinkEvent& event) { on_link_event(self, event); });
  {
    gst::GLibLocker lock(self);
    state->session = std::move(*session);
  }
  if (settings.takeControl && state->session->status().state == link::LinkState::Live &&
      !state->hasControl)
    state->session->requestControl();
  return TRUE;
}

static gboolean gst_wirc_control_stop(GstBaseTransform* transform) {
  auto* self = GST_WIRC_CONTROL(transform);
  auto* state = self->state;
  std::shared_ptr<link::VehicleLink> session;
  {
    gst::GLibLocker lock(self);
    session = std::move(state->session);
  }
  state->manual->release();
  if (session) {
    session->removeListener(state->sessionListener);
    session->setCommand(link::neutralPulses());
  }
  state->follower.reset();
  return TRUE;
}

// The follower's time: the buffer's running time, so that lost-timeout
// counts the stream's time (a test clock's, a replay's) and not this
// thread's. A buffer without a timestamp takes the pipeline clock's now.
static vision::TargetFollower::Clock::time_point running_time_of(GstBaseTransform* transform,
                                                                 GstBuffer* buffer) {
  GstClockTime time = GST_CLOCK_TIME_NONE;
  if (GST_BUFFER_PTS_IS_VALID(buffer) && transform->segment.format == GST_FORMAT_TIME)
    time =
        gst_segment_to_running_time(&transform->segment, GST_FORMAT_TIME, GST_BUFFER_PTS(buffer));
  if (!GST_CLOCK_TIME_IS_VALID(time)) {
    GstElement* element = GST_ELEMENT(transform);
    if (GstClock* clock = gst_element_get_clock(element)) {
      GstClockTime now = gst_clock_get_time(clock);
      GstClockTime base = gst_element_get_base_time(element);
      time = now > base ? now - base : 0;
      gst_object_unref(clock);
    }
  }
  if (!GST_CLOCK_TIME_IS_VALID(time)) time = 0;  // neither: a target seen is never lost by time
  return vision::TargetFollower::Clock::time_point(std::chrono::nanoseconds(time));
}

static GstFlowReturn gst_wirc_control_transform_ip(GstBaseTransform* transform, GstBuffer* buffer) {
  auto* self = GST_WIRC_CONTROL(transform);
  auto* state = self->state;
  bool changed = false;
  {
    // Copied only when a property changed, not per frame.
    gst::GLibLocker lock(self);
    if (state->settingsChanged || !state->follower) {
      state->active = state->settings;
      state->settingsChanged = false;
      changed = true;
    }
  }
  const Settings& settings = state->active;
  auto now = running_time_of(transform, buffer);
  // Time that steps back is a new stream (a flush, a restarted replay):
  // what was seen before it says nothing now.
  if (!state->follower || now < state->lastStep)
    state->follower.emplace(followConfig(settings), followerSettings(settings));
  else if (changed)
    state->follower->reconfigure(followConfig(settings), followerSettings(settings));
  state->lastStep = now;

  WircTagMeta* meta = gst_buffer_get_wirc_tag_meta(buffer);
  readSightings(meta, state->sightings);
  auto step =
      state->follower->step(state->sightings, meta ? static_cast<int>(meta->width) : 0, now);
  const auto& command = step.command;

  link::Pulses pulses = link::neutralPulses();
  pulses[settings.steeringChannel - 1] = command.steeringPulse;
  pulses[settings.throttleChannel - 1] = command.throttlePulse;
  // A command by hand holds the vehicle until its dead-man lapses.
  bool manual = state->manual->active();
  if (!manual) state->session->setCommand(pulses);

  bool steering =
      command.steeringPulse != settings.neutral || command.throttlePulse != settings.neutral;
  if (state->hasControl) {
    state->warnedWithoutControl = false;
  } else if (steering && !state->warnedWithoutControl) {
    state->warnedWithoutControl = true;
    GST_ELEMENT_WARNING(
        self, RESOURCE, WRITE, ("Steering without the control right"),
        ("The commands are not sent: another WiRC transmitter holds the right (emit "
         "request-control or set take-control=true to ask for it), or the BTEMP "
         "robot has not answered the registration yet."));
  }

  double sentSteering = command.steering, sentThrottle = command.throttle;
  auto sentSteeringPulse = static_cast<guint>(command.steeringPulse);
  auto sentThrottlePulse = static_cast<guint>(command.throttlePulse);
  if (manual) {
    std::lock_guard lock(state->manualMutex);
    sentSteering = state->manualSteering;
    sentThrottle = state->manualThrottle;
    sentSteeringPulse = state->manualSteeringPulse;
    sentThrottlePulse = state->manualThrottlePulse;
  }
  gst_element_post_message(
      GST_ELEMENT(self),
      gst_message_new_element(
          GST_OBJECT(self),
          gst_structure_new(
              wircam::bus::Control::kName, "timestamp", G_TYPE_UINT64, GST_BUFFER_PTS(buffer),
              "target-visible", G_TYPE_BOOLEAN, step.targetVisible, "enabled", G_TYPE_BOOLEAN,
              settings.enabled, "has-control", G_TYPE_BOOLEAN, state->hasControl.load(), "bearing",
              G_TYPE_DOUBLE, command.bearingRad, "distance", G_TYPE_DOUBLE, command.distance,
              "steering", G_TYPE_DOUBLE, sentSteering, "throttle", G_TYPE_DOUBLE, sentThrottle,
              "steering-pulse", G_TYPE_UINT, sentSteeringPulse, "throttle-pulse", G_TYPE_UINT,
              sentThrottlePulse, "manual", G_TYPE_BOOLEAN, manual, nullptr)));
  return GST_FLOW_OK;
}

// enabled=false stops the vehicle now, not at the next frame (which may be
// a frame period away, or never come on a stalled pipeline).
static void stop_following_now(GstWircControl* self) {
  std::shared_ptr<link::VehicleLink> session;
  link::Pulses pulses;
  {
    gst::GLibLocker lock(self);
    auto& s = self->state->settings;
    s.enabled = FALSE;
    self->state->settingsChanged = true;
    session = self->state->session;
    pulses = neutralOf(s);
  }
  // Not over a driver's command by hand: that one ends by its own dead-man.
  if (session && !self->state->manual->active()) session->setCommand(pulses);
}

static void gst_wirc_control_set_property(GObject* object, guint id, const GValue* value,
                                          GParamSpec* pspec) {
  auto* self = GST_WIRC_CONTROL(object);
  if (id == PROP_ENABLED && !g_value_get_boolean(value)) return stop_following_now(self);
  gst::GLibLocker lock(self);
  auto& s = self->state->settings;
  if (setProperty(id, value, s)) {
    if (id == PROP_KEEPALIVE) s.keepaliveSet = true;
  } else if (!gst::setLoginProperty(object, id, PROP_PERIODS, PROP_FAILSAFE, value, s)) {
    G_OBJECT_WARN_INVALID_PROPERTY_ID(object, id, pspec);
    return;
  }
  self->state->settingsChanged = true;
}

static void gst_wirc_control_get_property(GObject* object, guint id, GValue* value,
                                          GParamSpec* pspec) {
  auto* self = GST_WIRC_CONTROL(object);
  gst::GLibLocker lock(self);
  const auto& s = self->state->settings;
  if (getProperty(id, s, value)) return;
  if (id == PROP_HAS_CONTROL)
    g_value_set_boolean(value, self->state->hasControl.load());
  else if (!gst::getLoginProperty(id, PROP_PERIODS, PROP_FAILSAFE, value, s))
    G_OBJECT_WARN_INVALID_PROPERTY_ID(object, id, pspec);
}

static void gst_wirc_control_finalize(GObject* object) {
  delete GST_WIRC_CONTROL(object)->state;
  G_OBJECT_CLASS(gst_wirc_control_parent_class)->finalize(object);
}

static void gst_wirc_control_init(GstWircControl* self) {
  self->state = new WircControlState();
  self->state->manual = std::make_unique<gst::ManualDrive>(GST_ELEMENT(self), [self] {
    Settings settings;
    {
      gst::GLibLocker lock(self);
      settings = self->state->settings;
    }
    post_drive(self, "dead-man", neutralOf(settings), settings.steeringChannel,
               settings.throttleChannel);
  });
  gst_base_transform_set_passthrough(GST_BASE_TRANSFORM(self), TRUE);
}

static void gst_wirc_control_class_init(GstWircControlClass* klass) {
  auto* gobject = G_OBJECT_CLASS(klass);
  auto* element = GST_ELEMENT_CLASS(klass);
  gobject->set_property = gst_wirc_control_set_property;
  gobject->get_property = gst_wirc_control_get_property;
  gobject->finalize = gst_wirc_control_finalize;
  installProperties(gobject);
  hasControlSpec = g_param_spec_boolean(
      "has-control", "Has control",
      "Whether this transmitter holds the control right (only then do commands reach the "
      "vehicle)",
      FALSE, static_cast<GParamFlags>(G_PARAM_READABLE | G_PARAM_STATIC_STRINGS));
  g_object_class_install_property(gobject, PROP_HAS_CONTROL, hasControlSpec);
  /**
   * GstWircControl::request-control:
   *
   * Asks the device for the control right (AREQ). The answer is posted as a
   * `wirc-control-right` element message with `request` granted or denied.
   */
  signals[SIGNAL_REQUEST_CONTROL] = g_signal_new_class_handler(
      "request-control", G_TYPE_FROM_CLASS(klass),
      static_cast<GSignalFlags>(G_SIGNAL_RUN_LAST | G_SIGNAL_ACTION),
      G_CALLBACK(gst_wirc_control_request_control), nullptr, nullptr, nullptr, G_TYPE_NONE, 0);

  /**
   * GstWircControl::drive:
   * @steering: -1 (full right) .. 1 (full left)
   * @throttle: -1 (full reverse) .. 1 (full ahead), scaled by max-throttle
   *
   * Drives by hand: the command goes to the vehicle at once, through the
   * same pulse limits as the follower's, and holds for `drive-timeout` ms;
   * the follower keeps off meanwhile. Without a newer command by then the
   * vehicle goes to neutral. Send commands more often than that (every 100
   * ms, say) for as long as the driver drives. A value that is not a number
   * sends neutral. Each command is posted as a `wirc-drive` element message.
   * Returns whether the vehicle obeys (this transmitter holds the right).
   */
  signals[SIGNAL_DRIVE] =
      g_signal_new_class_handler("drive", G_TYPE_FROM_CLASS(klass),
                                 static_cast<GSignalFlags>(G_SIGNAL_RUN_LAST | G_SIGNAL_ACTION),
                                 G_CALLBACK(gst_wirc_control_drive), nullptr, nullptr, nullptr,
                                 G_TYPE_BOOLEAN, 2, G_TYPE_DOUBLE, G_TYPE_DOUBLE);

  gst_element_class_add_static_pad_template(element, &sink_template);
  gst_element_class_add_static_pad_template(element, &src_template);
  gst_element_class_set_static_metadata(
      element, "WiRC tag follower", "Filter/Control",
      "Steers a WiRC vehicle towards an AprilTag found by apriltagdetect", "wircam authors");
  auto* base = GST_BASE_TRANSFORM_CLASS(klass);
  base->start = gst_wirc_control_start;
  base->stop = gst_wirc_control_stop;
  base->transform_ip = gst_wirc_control_transform_ip;
  base->transform_ip_on_passthrough = TRUE;
  GST_DEBUG_CATEGORY_INIT(wirc_control_debug, "wirccontrol", 0, "WiRC tag follower");
}
