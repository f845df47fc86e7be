/**
 * SECTION:element-wircsrc
 *
 * Receives the camera stream of a WiRC device (or wirc-sim): logs in over
 * TCP (shared with every other wirc element naming the same device), asks
 * for camera `camera` with STST, reassembles the MJPEG-over-UDP packets and
 * pushes whole JPEG frames. Never pushes a corrupt or partial frame; every
 * dropped packet or frame is counted in `stats` and in a periodic
 * `wirc-stats` element message (which also carries the link state and
 * the device's last status report: battery-mv, analog-mv, inputs as bits).
 * Link events (state changes, the control right, refusals) come as
 * `wirc-session` element messages with `event` (text) and `state`.
 *
 * Going to PAUSED does not wait for the device: the login runs on the
 * process's event loop, and a device that is not logged in to within
 * `login-timeout` (or is lost with `reconnect=false`) ends the stream with
 * an error naming the cause, unless `wait-for-device` is set: then the
 * login is retried with backoff until the device appears (a recorder
 * started before its vehicle). A login the device refuses (an ERR answering
 * TL: unauthorised, busy) is a warning at once with the spec's meaning, is
 * retried at the backoff's pace, and is what the error names if no login
 * comes in time. Stopping sends EST and logs out, and never
 * waits on the network. The `end-of-stream` action signal ends the stream
 * from its own thread after the frames already whole (an application's
 * stop that never blocks, unlike sending EOS to a source whose thread is
 * held up downstream). Elements naming the same device share its login
 * only when the settings they were given agree (transmitter-name, priority,
 * reconnect, login-timeout, link-timeout, max-bad-messages, periods,
 * failsafe); a conflict is an error naming both elements.
 *
 * As a URI handler it takes wirc://HOST[:PORT]/CAMERA?device=NAME (an empty
 * HOST discovers the device named), so playbin and gst-play-1.0 play it.
 *
 * ## Example launch lines
 * |[
 * gst-launch-1.0 -e wircsrc host=127.0.0.1 ! jpegdec ! videoconvert ! autovideosink
 * ]|
 * |[
 * gst-play-1.0 wirc://192.168.1.1/0
 * ]|
 */
#include "gstwircsrc.h"

#include <algorithm>
#include <atomic>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>

#include "common/mutex.h"
#include "frame_buffers.h"
#include "gst_scoped.h"
#include "login_properties.h"
#include "wirc/frame_time.h"
#include "wirc/stream_inbox.h"
#include "wirc/transmitter_session.h"
#include "wirc_bus_messages.h"
#include "wirc_uri.h"
#include "wircsrc_settings.h"

GST_DEBUG_CATEGORY_STATIC(wirc_src_debug);
#define GST_CAT_DEFAULT wirc_src_debug

namespace {

using namespace wircam;
using Clock = std::chrono::steady_clock;
using namespace wircam::gst::wircsrc;

// The device reports every 500 ms: two missed reports make a status stale.
constexpr std::chrono::milliseconds kStatusStaleAfter{2 * wirc::kPsdPeriodMs};

// The C++ side of the element; GObject memory runs no constructors.
struct WircSrcState {
  Settings settings;  // guarded by the object lock

  // Streaming-thread state, set up in start() and torn down in stop().
  Settings active;  // what start() used: properties may change meanwhile
  std::shared_ptr<wirc::TransmitterSession> session;
  int sessionListener = 0;
  // Its wake-ups serve the element's life; its socket lives from start() to stop().
  wirc::StreamInbox inbox;
  // The frames' memory, back from the buffers downstream freed.
  std::shared_ptr<wirc::FrameBufferReturns> returns = std::make_shared<wirc::FrameBufferReturns>();
  Clock::time_point loginDeadline;
  bool streaming = false;  // the link was live and the camera exists
  int width = 0;
  int height = 0;
  Clock::time_point nextStats;
  GstClockTime lastPts = GST_CLOCK_TIME_NONE;  // the newest frame's, on the streaming thread
  // When the last frame was taken, and the frames' interval (smoothed): the
  // link's keepalive rides on this thread's turns (shareTurn).
  std::optional<Clock::time_point> lastFrameTaken;
  Clock::duration frameInterval{};
  // Whether the pipeline's clock reads CLOCK_MONOTONIC, asked once per clock
  // (a property read per frame cost more than the rest of the timestamp).
  const GstClock* typedClock = nullptr;
  bool monotonicClock = false;

  Mutex refusalMutex;                                   // refusal is written on the event loop
  std::string refusal WIRCAM_GUARDED_BY(refusalMutex);  // the device refused this camera's STST
  // The device's answer to the last login it refused (TL), reported at once
  // and named again if no login comes in time.
  std::string loginRefusal WIRCAM_GUARDED_BY(refusalMutex);

  Mutex statsMutex;  // the stats property reads the copy
  wirc::StreamReceiverStats stats WIRCAM_GUARDED_BY(statsMutex);
};

}  // namespace

struct _GstWircSrc {
  GstPushSrc parent;
  WircSrcState* state;
};

G_DEFINE_TYPE_WITH_CODE(GstWircSrc, gst_wirc_src, GST_TYPE_PUSH_SRC,
                        G_IMPLEMENT_INTERFACE(GST_TYPE_URI_HANDLER, gst::initWircUriHandler))

static GstStaticPadTemplate src_template =
    GST_STATIC_PAD_TEMPLATE("src", GST_PAD_SRC, GST_PAD_ALWAYS, GST_STATIC_CAPS("image/jpeg"));

namespace {

void publishStats(GstWircSrc* self) {
  auto* state = self->state;
  MutexLock lock(state->statsMutex);
  state->stats = state->inbox.receiver().stats();
}

void postStats(GstWircSrc* self) {
  auto* state = self->state;
  GstStructure* stats;
  {
    MutexLock lock(state->statsMutex);
    stats = gst::statsStructure(state->stats.assembler, state->stats.packetsForeign);
  }
  // The device's latest status report rides along, for recorders and UIs.
  auto session = state->session->sessionStatus();
  gst_structure_set(stats, "session", G_TYPE_STRING, link::linkStateName(session.state), nullptr);
  if (const auto& psd = session.lastStatus) {
    // A report the device stopped renewing is shown with its age, as stale.
    auto age = std::chrono::duration_cast<std::chrono::milliseconds>(Clock::now() -
                                                                     session.telemetry->received);
    gst_structure_set(stats, "battery-mv", G_TYPE_UINT, static_cast<guint>(psd->batteryMillivolts),
                      "analog-mv", G_TYPE_UINT, static_cast<guint>(psd->analogMillivolts), "inputs",
                      G_TYPE_UINT, static_cast<guint>(*session.telemetry->inputs), "status-age-ms",
                      G_TYPE_UINT64, static_cast<guint64>(age.count()), "status-stale",
                      G_TYPE_BOOLEAN, age > kStatusStaleAfter, nullptr);
  }
  // Every PCD the link sent the vehicle, repeats (keepalives) included.
  gst_structure_set(stats, "input-rejected", G_TYPE_UINT64,
                    static_cast<guint64>(session.inputRejected), "commands-sent", G_TYPE_UINT64,
                    static_cast<guint64>(session.commandsSent), nullptr);
  gst_element_post_message(GST_ELEMENT(self), gst_message_new_element(GST_OBJECT(self), stats));
}

// Link events reach the application as "wirc-session" element messages
// and wake the streaming thread when they change what it must do.
void onLinkEvent(GstWircSrc* self, const link::LinkEvent& event) {
  auto* state = self->state;
  if (std::holds_alternative<link::TelemetryReceived>(event)) return;  // in wirc-stats
  std::string text = link::describe(event);
  GST_INFO_OBJECT(self, "link: %s", text.c_str());
  GstStructure* s =
      gst_structure_new(wircam::bus::Session::kName, "event", G_TYPE_STRING, text.c_str(), nullptr);
  if (const auto* changed = std::get_if<link::StateChanged>(&event)) {
    state->inbox.linkChanged();
    gst_structure_set(s, "state", G_TYPE_STRING, link::linkStateName(changed->state), "reason",
                      G_TYPE_STRING, changed->reason.c_str(), nullptr);
  }
  if (const auto* refused = std::get_if<link::DeviceRefused>(&event);
      refused && refused->request == "STST") {
    {
      MutexLock lock(state->refusalMutex);
      state->refusal = text;
    }
    state->inbox.linkChanged();
  }
  if (const auto* refused = std::get_if<link::DeviceRefused>(&event);
      refused && refused->request == "TL") {
    // The device's own answer, not a network fault: said at once (once for
    // each different answer), while the link retries at its backoff's pace.
    bool first;
    {
      MutexLock lock(state->refusalMutex);
      first = state->loginRefusal != refused->meaning;
      state->loginRefusal = refused->meaning;
    }
    if (first)
      GST_ELEMENT_WARNING(self, RESOURCE, OPEN_READ,
                          ("The WiRC device refused the login: %s (ERR %d)",
                           refused->meaning.c_str(), refused->code),
                          ("Retrying with backoff; the device's answer is in the link state. "
                           "ERR %d is the device's own refusal (see its transmitter list and "
                           "priority), not a network fault.",
                           refused->code));
  }
  gst_element_post_message(GST_ELEMENT(self), gst_message_new_element(GST_OBJECT(self), s));
}

bool openStreamSocket(GstWircSrc* self, const Settings& settings) {
  auto& inbox = self->state->inbox;
  if (auto error =
          inbox.open(static_cast<uint16_t>(settings.streamPort),
                     {.frameTimeout = std::chrono::milliseconds(settings.frameTimeoutMs)})) {
    GST_ELEMENT_ERROR(self, RESOURCE, OPEN_READ, ("Could not open the stream port"),
                      ("%s. Set stream-port=0 to pick a free port.", error->c_str()));
    return false;
  }
  constexpr int wanted = wirc::StreamInbox::kReceiveBufferBytes;
  if (int granted = inbox.receiveBufferBytes(); granted < wanted)
    GST_ELEMENT_WARNING(self, RESOURCE, SETTINGS, ("Small UDP receive buffer"),
                        ("The kernel capped it at %d bytes (wanted %d): frames may be lost in "
                         "bursts. Raise it with: sysctl -w net.core.rmem_max=%d",
                         granted, wanted, wanted));
  return true;
}

}  // namespace

static gboolean gst_wirc_src_start(GstBaseSrc* base) {
  auto* self = GST_WIRC_SRC(base);
  auto* state = self->state;
  {
    gst::GLibLocker lock(self);
    state->active = state->settings;
  }
  const Settings& settings = state->active;
  // Waiting for a device is trying again: without reconnect the first
  // refused connection ended it, said only as "Could not log in".
  if (settings.waitForDevice && !settings.reconnect) {
    GST_ELEMENT_ERROR(self, RESOURCE, SETTINGS, ("wait-for-device=true needs reconnect=true"),
                      ("waiting for a device is logging in again until it answers"));
    return FALSE;
  }

  auto session = wirc::TransmitterSession::acquire(sessionConfig(settings), GST_OBJECT_NAME(self));
  if (!session) {
    GST_ELEMENT_ERROR(self, RESOURCE, SETTINGS, ("Cannot use the WiRC device's link"),
                      ("%s", session.error().c_str()));
    return FALSE;
  }
  if (!openStreamSocket(self, settings)) return FALSE;
  state->session = std::move(*session);
  state->inbox.clearEndRequest();
  state->streaming = false;
  {
    MutexLock lock(state->refusalMutex);
    state->refusal.clear();
    state->loginRefusal.clear();
  }
  state->width = state->height = 0;
  state->lastPts = GST_CLOCK_TIME_NONE;
  state->lastFrameTaken.reset();
  state->typedClock = nullptr;  // a new clock may come at a freed one's address
  state->loginDeadline = Clock::now() + std::chrono::milliseconds(settings.loginTimeoutMs + 500);
  state->nextStats = Clock::now() + std::chrono::milliseconds(settings.statsIntervalMs);
  publishStats(self);
  // A login made before this element listened (its own, done quickly, or
  // another element's it joined) is heard from addListener() itself.
  state->sessionListener = state->session->addListener(
      [self](const link::LinkEvent& event) { onLinkEvent(self, event); });
  // The session sends STST once logged in, and again after each reconnect.
  uint16_t port = state->inbox.port();
  state->session->startStream(static_cast<uint8_t>(settings.camera), port);
  GST_INFO_OBJECT(self, "camera %u will stream to port %u", settings.camera, port);
  return TRUE;
}

static gboolean gst_wirc_src_stop(GstBaseSrc* base) {
  auto* self = GST_WIRC_SRC(base);
  auto* state = self->state;
  if (state->session) {
    state->session->removeListener(state->sessionListener);
    state->session->stopStream(static_cast<uint8_t>(state->active.camera));
    state->session.reset();  // the last user's release logs out, without waiting
  }
  if (state->inbox.isOpen()) publishStats(self);
  state->inbox.close();
  return TRUE;
}

static gboolean gst_wirc_src_unlock(GstBaseSrc* base) {
  GST_WIRC_SRC(base)->state->inbox.interrupt();
  return TRUE;
}

static gboolean gst_wirc_src_unlock_stop(GstBaseSrc* base) {
  GST_WIRC_SRC(base)->state->inbox.clearInterrupt();
  return TRUE;
}

static void gst_wirc_src_end_of_stream(GstWircSrc* self) { self->state->inbox.requestEnd(); }

static gboolean gst_wirc_src_query(GstBaseSrc* base, GstQuery* query) {
  if (GST_QUERY_TYPE(query) == GST_QUERY_LATENCY) {
    // Frames are stamped when their first packet arrives and pushed when the
    // last one does; an incomplete frame waits at most frame-timeout.
    guint timeout;
    {
      gst::GLibLocker lock(base);
      timeout = GST_WIRC_SRC(base)->state->settings.frameTimeoutMs;
    }
    gst_query_set_latency(query, TRUE, 0, timeout * GST_MSECOND);
    return TRUE;
  }
  return GST_BASE_SRC_CLASS(gst_wirc_src_parent_class)->query(base, query);
}

// What the link says: FLOW_OK to go on (streaming says whether frames can
// come), or an error already posted.
static GstFlowReturn follow_link(GstWircSrc* self) {
  auto* state = self->state;
  const Settings& settings = state->active;
  auto status = state->session->sessionStatus();
  const char* where = settings.host.empty() ? "(discovery)" : settings.host.c_str();
  std::string loginRefusal;
  {
    MutexLock lock(state->refusalMutex);
    loginRefusal = state->loginRefusal;
  }
  bool noLoginYet = status.logins == 0 && status.state != link::LinkState::Live;
  if (noLoginYet && !loginRefusal.empty() &&
      (status.state == link::LinkState::Failed ||
       (!settings.waitForDevice && Clock::now() >= state->loginDeadline))) {
    GST_ELEMENT_ERROR(self, RESOURCE, OPEN_READ,
                      ("The WiRC device %s refused the login: %s", where, loginRefusal.c_str()),
                      ("%s", status.reason.c_str()));
    return GST_FLOW_ERROR;
  }
  // What to check: the address given, or (discovering) the device's name
  // and the discovery address.
  const char* check = settings.host.empty()
                          ? "Check the device is on and on this network (device=, "
                            "discovery-address=), or give its host="
                          : "Check host/port, or leave host empty to discover the device";
  if (status.state == link::LinkState::Failed) {
    if (status.logins == 0)
      GST_ELEMENT_ERROR(self, RESOURCE, OPEN_READ,
                        ("Could not log in to the WiRC device %s", where),
                        ("%s. %s.", status.reason.c_str(), check));
    else
      GST_ELEMENT_ERROR(self, RESOURCE, READ, ("Lost the WiRC device %s", where),
                        ("%s (reconnect=false)", status.reason.c_str()));
    return GST_FLOW_ERROR;
  }
  if (status.state != link::LinkState::Live) {
    if (status.logins == 0 && !settings.waitForDevice && Clock::now() >= state->loginDeadline) {
      GST_ELEMENT_ERROR(self, RESOURCE, OPEN_READ,
                        ("Could not log in to the WiRC device %s", where),
                        ("no login within %u ms (login-timeout)%s%s. %s.", settings.loginTimeoutMs,
                         status.reason.empty() ? "" : ": ", status.reason.c_str(), check));
      return GST_FLOW_ERROR;
    }
    return GST_FLOW_OK;
  }
  if (settings.camera >= status.cameraCount) {
    GST_ELEMENT_ERROR(
        self, RESOURCE, SETTINGS, ("The device has no camera %u", settings.camera),
        ("It reports %u camera(s): set camera=0..%d", status.cameraCount, status.cameraCount - 1));
    return GST_FLOW_ERROR;
  }
  // Checked after the camera count, which explains a refusal of a camera
  // the device does not have better than the refusal does.
  {
    MutexLock lock(state->refusalMutex);
    if (!state->refusal.empty()) {
      GST_ELEMENT_ERROR(self, RESOURCE, OPEN_READ,
                        ("The device refused camera %u", settings.camera),
                        ("%s", state->refusal.c_str()));
      return GST_FLOW_ERROR;
    }
  }
  // After a reconnect the device streams from a new port.
  state->inbox.receiver().follow(*state->session->deviceAddress(), status.logins);
  state->streaming = true;
  return GST_FLOW_OK;
}

// The pipeline clock's time at which a frame's first packet arrived. With
// GStreamer's monotonic system clock (what a pipeline uses unless told
// otherwise) that is the arrival time itself: steady_clock reads the same
// CLOCK_MONOTONIC, so the time is exact however loaded the machine. With any
// other clock: its now less the frame's age, the two read back to back.
static GstClockTime arrival_clock_time(GstClock* clock, bool monotonic,
                                       Clock::time_point firstPacket) {
  auto sinceBoot =
      std::chrono::duration_cast<std::chrono::nanoseconds>(firstPacket.time_since_epoch());
  if (monotonic) {
    GstClockTime internal, external, rateNum, rateDenom;
    gst_clock_get_calibration(clock, &internal, &external, &rateNum, &rateDenom);
    return gst_clock_adjust_with_calibration(clock, static_cast<GstClockTime>(sinceBoot.count()),
                                             internal, external, rateNum, rateDenom);
  }
  GstClockTime now = gst_clock_get_time(clock);
  auto age = std::max<int64_t>(
      0, std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - firstPacket).count());
  return now > static_cast<GstClockTime>(age) ? now - static_cast<GstClockTime>(age) : 0;
}

// A frame's running time: when its first packet arrived, rising by at least
// a millisecond from frame to frame (wirc::nextFrameTime).
static GstClockTime frame_timestamp(GstWircSrc* self, Clock::time_point firstPacket) {
  GstClock* clock = gst_element_get_clock(GST_ELEMENT(self));
  if (!clock) return GST_CLOCK_TIME_NONE;
  auto* state = self->state;
  if (clock != state->typedClock) {
    GstClockType type = GST_CLOCK_TYPE_REALTIME;
    if (GST_IS_SYSTEM_CLOCK(clock)) g_object_get(clock, "clock-type", &type, nullptr);
    state->typedClock = clock;
    state->monotonicClock = type == GST_CLOCK_TYPE_MONOTONIC;
  }
  GstClockTime arrival = arrival_clock_time(clock, state->monotonicClock, firstPacket);
  gst_object_unref(clock);
  GstClockTime base = gst_element_get_base_time(GST_ELEMENT(self));
  auto& last = state->lastPts;
  std::optional<uint64_t> previous;
  if (GST_CLOCK_TIME_IS_VALID(last)) previous = last;
  last = wirc::nextFrameTime(arrival > base ? arrival - base : 0, previous);
  return last;
}

// This thread wakes for every frame anyway: a keepalive due before the
// next frame leaves on this turn, and the link's event loop sleeps on (at
// CIF/15 its keepalive timer was 0.7 wake-ups a frame, a third of the
// receiving process's CPU).
static void share_turn_with_link(WircSrcState* state) {
  auto now = Clock::now();
  if (state->lastFrameTaken)
    state->frameInterval = (3 * state->frameInterval + (now - *state->lastFrameTaken)) / 4;
  state->lastFrameTaken = now;
  state->session->shareTurn(state->frameInterval);
}

static GstFlowReturn gst_wirc_src_create(GstPushSrc* pushsrc, GstBuffer** out) {
  auto* self = GST_WIRC_SRC(pushsrc);
  auto* state = self->state;
  auto intervalMs = state->active.statsIntervalMs;
  bool checkLink = !state->streaming;

  while (auto spare = state->returns->take()) state->inbox.receiver().recycle(std::move(*spare));
  std::optional<wirc::AssembledFrame> frame;
  while (!(frame = state->inbox.takeFrame())) {
    if (checkLink) {
      if (GstFlowReturn flow = follow_link(self); flow != GST_FLOW_OK) return flow;
      checkLink = false;
    }
    // Until the first login, this wait's bound is what checks its deadline.
    switch (state->inbox.wait(Clock::now() + std::chrono::milliseconds(100))) {
      case wirc::StreamInbox::Wake::Interrupted:
        return GST_FLOW_FLUSHING;
      case wirc::StreamInbox::Wake::EndRequested:
        return GST_FLOW_EOS;  // basesrc pushes the EOS
      case wirc::StreamInbox::Wake::LinkChanged:
        checkLink = true;
        break;
      case wirc::StreamInbox::Wake::Frame:
      case wirc::StreamInbox::Wake::Deadline:
        checkLink = !state->streaming;
        break;
    }
    if (intervalMs > 0 && Clock::now() >= state->nextStats) {
      state->nextStats = Clock::now() + std::chrono::milliseconds(intervalMs);
      publishStats(self);
      postStats(self);
    }
  }
  publishStats(self);
  share_turn_with_link(state);

  GstClockTime pts = frame_timestamp(self, frame->firstPacketTime);
  bool discont = frame->discont;
  GstBuffer* buffer = gst::wrapFrame(std::move(*frame), state->returns);

  if (GstCaps* caps = gst::jpegCapsIfChanged(buffer, state->width, state->height)) {
    gst_base_src_set_caps(GST_BASE_SRC(self), caps);
    gst_caps_unref(caps);
  }
  GST_BUFFER_PTS(buffer) = pts;
  if (discont) GST_BUFFER_FLAG_SET(buffer, GST_BUFFER_FLAG_DISCONT);
  *out = buffer;
  return GST_FLOW_OK;
}

static gboolean gst_wirc_src_negotiate(GstBaseSrc*) {
  // Caps come from each frame's SOF marker, set in create().
  return TRUE;
}

static void gst_wirc_src_set_property(GObject* object, guint id, const GValue* value,
                                      GParamSpec* pspec) {
  auto* self = GST_WIRC_SRC(object);
  {
    // The login and the stream use what start() read: a change now would
    // show in the property but not on the wire, so it is refused, saying so.
    gst::GLibLocker lock(self);
    bool running = GST_STATE(self) > GST_STATE_READY || GST_STATE_PENDING(self) > GST_STATE_READY;
    if (running && (pspec->flags & GST_PARAM_MUTABLE_READY)) {
      GST_WARNING_OBJECT(self, "%s cannot change while streaming", pspec->name);
      g_warning(
          "%s: %s cannot change while the element is PAUSED or PLAYING; set it in "
          "NULL or READY",
          GST_OBJECT_NAME(self), pspec->name);
      return;
    }
  }
  gst::GLibLocker lock(self);
  auto& s = self->state->settings;
  if (id == PROP_TRANSMITTER_NAME) {
    const char* name = g_value_get_string(value) ? g_value_get_string(value) : "";
    if (auto tl = wirc::encode(wirc::Tl{.name = name}); !tl) {
      g_warning("wircsrc %s: transmitter-name '%s' refused, kept '%s': %s", GST_OBJECT_NAME(self),
                name, s.transmitterName.c_str(), tl.error().message().c_str());
      return;
    }
  }
  if (setProperty(id, value, s)) {
    if (isLinkSetting(id)) s.given.insert(pspec->name);
  } else if (!gst::setLoginProperty(object, id, PROP_PERIODS, PROP_FAILSAFE, value, s)) {
    G_OBJECT_WARN_INVALID_PROPERTY_ID(object, id, pspec);
  }
}

static void gst_wirc_src_get_property(GObject* object, guint id, GValue* value, GParamSpec* pspec) {
  auto* self = GST_WIRC_SRC(object);
  if (id == PROP_STATS) {
    auto* state = self->state;
    MutexLock lock(state->statsMutex);
    g_value_take_boxed(value,
                       gst::statsStructure(state->stats.assembler, state->stats.packetsForeign));
    return;
  }
  gst::GLibLocker lock(self);
  const auto& s = self->state->settings;
  if (getProperty(id, s, value)) return;
  if (!gst::getLoginProperty(id, PROP_PERIODS, PROP_FAILSAFE, value, s))
    G_OBJECT_WARN_INVALID_PROPERTY_ID(object, id, pspec);
}

static void gst_wirc_src_finalize(GObject* object) {
  delete GST_WIRC_SRC(object)->state;
  G_OBJECT_CLASS(gst_wirc_src_parent_class)->finalize(object);
}

static void gst_wirc_src_init(GstWircSrc* self) {
  self->state = new WircSrcState();
  gst_base_src_set_live(GST_BASE_SRC(self), TRUE);
  gst_base_src_set_format(GST_BASE_SRC(self), GST_FORMAT_TIME);
}

static void gst_wirc_src_class_init(GstWircSrcClass* klass) {
  auto* gobject = G_OBJECT_CLASS(klass);
  auto* element = GST_ELEMENT_CLASS(klass);
  auto* basesrc = GST_BASE_SRC_CLASS(klass);
  auto* pushsrc = GST_PUSH_SRC_CLASS(klass);

  gobject->set_property = gst_wirc_src_set_property;
  gobject->get_property = gst_wirc_src_get_property;
  gobject->finalize = gst_wirc_src_finalize;

  installProperties(gobject);
  g_object_class_install_property(
      gobject, PROP_STATS,
      g_param_spec_boxed(
          "stats", "Statistics",
          "Counters: packets, bytes, frames-complete, "
          "frames-incomplete, packets-duplicate, packets-invalid, packets-foreign, ...",
          GST_TYPE_STRUCTURE, static_cast<GParamFlags>(G_PARAM_READABLE | G_PARAM_STATIC_STRINGS)));
  g_signal_new_class_handler("end-of-stream", G_TYPE_FROM_CLASS(klass),
                             static_cast<GSignalFlags>(G_SIGNAL_RUN_LAST | G_SIGNAL_ACTION),
                             G_CALLBACK(gst_wirc_src_end_of_stream), nullptr, nullptr, nullptr,
                             G_TYPE_NONE, 0);

  gst_element_class_add_static_pad_template(element, &src_template);
  gst_element_class_set_static_metadata(
      element, "WiRC camera source", "Source/Network",
      "Receives the MJPEG stream of a WiRC device camera as whole JPEG frames", "wircam authors");

  basesrc->start = gst_wirc_src_start;
  basesrc->stop = gst_wirc_src_stop;
  basesrc->unlock = gst_wirc_src_unlock;
  basesrc->unlock_stop = gst_wirc_src_unlock_stop;
  basesrc->query = gst_wirc_src_query;
  basesrc->negotiate = gst_wirc_src_negotiate;
  pushsrc->create = gst_wirc_src_create;

  GST_DEBUG_CATEGORY_INIT(wirc_src_debug, "wircsrc", 0, "WiRC camera source");
}
