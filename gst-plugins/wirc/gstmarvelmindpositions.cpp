/**
 * SECTION:element-marvelmindpositions
 *
 * Asks a Marvelmind dashboard where the vehicle's beacons are (or listens
 * to a dashboard that pushes them) and joins the positions to the video
 * that passes through, untouched: each buffer gets a WircPositionMeta per
 * beacon, the position measured nearest to the buffer's time among those
 * received so far (with polling at R Hz, at most about 1/R s apart), and
 * each new position is posted as a "marvelmind-position" element message
 * (beacon, x, y, z in metres, timestamp: the dashboard's seconds,
 * running-time). A beacon with no new position for stale-timeout is posted
 * as "marvelmind-stale" (beacon, reason) and no longer joined to buffers.
 * Replies with a bad CRC, wrong type, code, size or beacon, and datagrams
 * from anyone but the dashboard, are counted in stats and dropped.
 *
 * ## Example launch lines
 * |[
 * gst-launch-1.0 -m wircsrc host=192.168.1.1 ! marvelmindpositions host=192.168.1.50 beacons=5 ! tjpegdec ! tagoverlay ! autovideosink
 * ]|
 * |[
 * gst-launch-1.0 -m wircsrc ! marvelmindpositions mode=stream listen-port=49100 host=192.168.1.50 beacons=5,6 ! fakesink
 * ]|
 */
#include "gstmarvelmindpositions.h"

#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "common/mutex.h"
#include "gst_scoped.h"
#include "marvelmind/position_client.h"
#include "wirc_bus_messages.h"
#include "wirc_position_meta.h"

GST_DEBUG_CATEGORY_STATIC(marvelmind_positions_debug);
#define GST_CAT_DEFAULT marvelmind_positions_debug

namespace {

using namespace wircam;
namespace mm = marvelmind;

#define DEFAULT_HOST "127.0.0.1"
#define DEFAULT_BEACONS "5"
#define DEFAULT_POLL_RATE 10.0
#define DEFAULT_STALE_TIMEOUT 1000

enum {
  PROP_0,
  PROP_HOST,
  PROP_PORT,
  PROP_BEACONS,
  PROP_MODE,
  PROP_LISTEN_PORT,
  PROP_POLL_RATE,
  PROP_UNITS,
  PROP_TIMESTAMP_UNIT,
  PROP_STALE_TIMEOUT,
  PROP_STATS,
};

GType modeType() {
  static GType type = [] {
    static const GEnumValue values[] = {
        {static_cast<gint>(mm::Mode::kPoll), "Ask the dashboard at poll-rate", "poll"},
        {static_cast<gint>(mm::Mode::kStream), "Listen on listen-port to a pushing dashboard",
         "stream"},
        {0, nullptr, nullptr}};
    return g_enum_register_static("GstMarvelmindMode", values);
  }();
  return type;
}

GType unitsType() {
  static GType type = [] {
    static const GEnumValue values[] = {
        {static_cast<gint>(mm::Resolution::kCentimetres), "Centimetres (code 0x0001)", "cm"},
        {static_cast<gint>(mm::Resolution::kMillimetres), "Millimetres (code 0x0011)", "mm"},
        {0, nullptr, nullptr}};
    return g_enum_register_static("GstMarvelmindUnits", values);
  }();
  return type;
}

GType timestampUnitType() {
  static GType type = [] {
    static const GEnumValue values[] = {{static_cast<gint>(mm::TimestampUnit::kSixtyFourths),
                                         "1/64 s (the protocol text)", "sixty-fourths"},
                                        {static_cast<gint>(mm::TimestampUnit::kMilliseconds),
                                         "Milliseconds (newer dashboards)", "milliseconds"},
                                        {0, nullptr, nullptr}};
    return g_enum_register_static("GstMarvelmindTimestampUnit", values);
  }();
  return type;
}

// How many positions per beacon are kept to match frames against: at 100 Hz
// a little over half a second, more than any frame waits.
constexpr size_t kHistory = 64;

struct PositionsState {
  mm::ClientConfig config;  // guarded by the object lock
  bool running = false;     // guarded by the object lock: settings are fixed then
  Mutex mutex;              // never held while the client is destroyed
  std::map<uint8_t, std::deque<mm::Position>> history WIRCAM_GUARDED_BY(mutex);
  std::shared_ptr<mm::PositionClient> client WIRCAM_GUARDED_BY(mutex);
};

std::string beaconList(const std::vector<uint8_t>& beacons) {
  std::string text;
  for (uint8_t beacon : beacons) text += (text.empty() ? "" : ",") + std::to_string(beacon);
  return text;
}

}  // namespace

struct _GstMarvelmindPositions {
  GstBaseTransform parent;
  PositionsState* state;
};

G_DEFINE_TYPE(GstMarvelmindPositions, gst_marvelmind_positions, GST_TYPE_BASE_TRANSFORM)

static GstStaticPadTemplate sink_template =
    GST_STATIC_PAD_TEMPLATE("sink", GST_PAD_SINK, GST_PAD_ALWAYS, GST_STATIC_CAPS_ANY);
static GstStaticPadTemplate src_template =
    GST_STATIC_PAD_TEMPLATE("src", GST_PAD_SRC, GST_PAD_ALWAYS, GST_STATIC_CAPS_ANY);

// The pipeline's running time of an instant on the steady clock; none
// before PLAYING (the base time is not set yet).
static GstClockTime running_time_of(GstElement* element, mm::Clock::time_point instant) {
  GstState current;
  {
    gst::GLibLocker lock(element);
    current = GST_STATE(element);
  }
  if (current != GST_STATE_PLAYING) return GST_CLOCK_TIME_NONE;
  GstClock* clock = gst_element_get_clock(element);
  if (!clock) return GST_CLOCK_TIME_NONE;
  GstClockTime now = gst_clock_get_time(clock);
  gst_object_unref(clock);
  GstClockTime base = gst_element_get_base_time(element);
  auto ago = std::chrono::duration_cast<std::chrono::nanoseconds>(mm::Clock::now() - instant);
  auto sinceBase = static_cast<int64_t>(now - base) - ago.count();
  return sinceBase < 0 ? 0 : static_cast<GstClockTime>(sinceBase);
}

static void on_position_event(GstMarvelmindPositions* self, const mm::PositionEvent& event) {
  auto* state = self->state;
  GstStructure* s = nullptr;
  if (const auto* received = std::get_if<mm::PositionReceived>(&event)) {
    const auto& p = received->position;
    GstClockTime runningTime = running_time_of(GST_ELEMENT(self), p.measured);
    {
      MutexLock lock(state->mutex);
      auto& history = state->history[p.beacon];
      history.push_back(p);
      if (history.size() > kHistory) history.pop_front();
    }
    s = gst_structure_new(wircam::bus::Position::kName, "beacon", G_TYPE_UINT, guint{p.beacon}, "x",
                          G_TYPE_DOUBLE, p.x, "y", G_TYPE_DOUBLE, p.y, "z", G_TYPE_DOUBLE, p.z,
                          "timestamp", G_TYPE_DOUBLE, p.timestamp, "running-time", G_TYPE_UINT64,
                          runningTime, nullptr);
  } else if (const auto* stale = std::get_if<mm::PositionStale>(&event)) {
    GST_INFO_OBJECT(self, "beacon %u: %s", stale->beacon, stale->reason.c_str());
    {
      MutexLock lock(state->mutex);
      state->history.erase(stale->beacon);
    }
    s = gst_structure_new(wircam::bus::PositionStale::kName, "beacon", G_TYPE_UINT,
                          guint{stale->beacon}, "reason", G_TYPE_STRING, stale->reason.c_str(),
                          nullptr);
  }
  if (s) gst_element_post_message(GST_ELEMENT(self), gst_message_new_element(GST_OBJECT(self), s));
}

static gboolean gst_marvelmind_positions_start(GstBaseTransform* transform) {
  auto* self = GST_MARVELMIND_POSITIONS(transform);
  mm::ClientConfig config;
  {
    gst::GLibLocker lock(self);
    config = self->state->config;
  }
  if (config.mode == mm::Mode::kPoll && config.port == 0) config.port = mm::kDefaultDashboardPort;
  auto client = mm::PositionClient::start(
      config, [self](const mm::PositionEvent& event) { on_position_event(self, event); });
  if (!client) {
    GST_ELEMENT_ERROR(self, RESOURCE, SETTINGS, ("Cannot ask the Marvelmind dashboard"),
                      ("%s", client.error().c_str()));
    return FALSE;
  }
  GST_INFO_OBJECT(self, "%s %s for beacon(s) %s, replies on port %u",
                  config.mode == mm::Mode::kPoll ? "polling" : "listening to",
                  config.dashboard().c_str(), beaconList(config.beacons).c_str(),
                  (*client)->localPort());
  {
    MutexLock lock(self->state->mutex);
    self->state->client = std::move(*client);
  }
  gst::GLibLocker lock(self);
  self->state->running = true;
  return TRUE;
}

static gboolean gst_marvelmind_positions_stop(GstBaseTransform* transform) {
  auto* self = GST_MARVELMIND_POSITIONS(transform);
  auto* state = self->state;
  std::shared_ptr<mm::PositionClient> client;
  {
    MutexLock lock(state->mutex);
    client = std::move(state->client);
    state->history.clear();
  }
  client.reset();  // waits for a running listener, which takes the mutex
  gst::GLibLocker lock(self);
  state->running = false;
  return TRUE;
}

// The instant on the steady clock of a running time, while PLAYING.
static std::optional<mm::Clock::time_point> steady_time_of(GstElement* element,
                                                           GstClockTime runningTime) {
  GstClock* clock = gst_element_get_clock(element);
  if (!clock) return std::nullopt;
  auto steadyNow = mm::Clock::now();
  GstClockTime now = gst_clock_get_time(clock);
  gst_object_unref(clock);
  auto ago = static_cast<int64_t>(now - gst_element_get_base_time(element)) -
             static_cast<int64_t>(runningTime);
  return steadyNow - std::chrono::nanoseconds(ago);
}

static GstFlowReturn gst_marvelmind_positions_transform_ip(GstBaseTransform* transform,
                                                           GstBuffer* buffer) {
  auto* state = GST_MARVELMIND_POSITIONS(transform)->state;
  GstClockTime frameTime =
      gst_segment_to_running_time(&transform->segment, GST_FORMAT_TIME, GST_BUFFER_PTS(buffer));
  if (!GST_CLOCK_TIME_IS_VALID(frameTime)) return GST_FLOW_OK;
  // Matched on the steady clock, where the client stamps its positions.
  auto frameInstant = steady_time_of(GST_ELEMENT(transform), frameTime);
  if (!frameInstant) return GST_FLOW_OK;
  MutexLock lock(state->mutex);
  for (const auto& [beacon, history] : state->history) {
    const mm::Position* nearest = nullptr;
    auto best = mm::Clock::duration::max();
    for (const auto& position : history) {
      auto distance = std::chrono::abs(*frameInstant - position.measured);
      if (distance < best) best = distance, nearest = &position;
    }
    if (!nearest) continue;
    auto offset =
        std::chrono::duration_cast<std::chrono::nanoseconds>(*frameInstant - nearest->measured)
            .count();
    WircPositionMeta* meta = gst_buffer_add_wirc_position_meta(buffer);
    meta->beacon = beacon;
    meta->x = nearest->x;
    meta->y = nearest->y;
    meta->z = nearest->z;
    meta->dashboard_time = nearest->timestamp;
    meta->offset = offset;
    meta->running_time = offset <= static_cast<int64_t>(frameTime)
                             ? frameTime - static_cast<GstClockTime>(offset)
                             : 0;
  }
  return GST_FLOW_OK;
}

static GstStructure* stats_structure(GstMarvelmindPositions* self) {
  mm::ClientStats stats;
  std::shared_ptr<mm::PositionClient> client;
  {
    MutexLock lock(self->state->mutex);
    client = self->state->client;
  }
  if (client) stats = client->stats();
  GstStructure* s =
      gst_structure_new("marvelmind-stats", "requests", G_TYPE_UINT64, stats.requests, "replies",
                        G_TYPE_UINT64, stats.replies, "positions", G_TYPE_UINT64, stats.positions,
                        "repeats", G_TYPE_UINT64, stats.repeats, "rejected", G_TYPE_UINT64,
                        stats.rejectedTotal(), "foreign", G_TYPE_UINT64, stats.foreign, nullptr);
  for (const auto& [reason, count] : stats.rejected) {
    std::string field = "rejected-" + reason;
    for (char& c : field)
      if (c == ' ') c = '-';
    gst_structure_set(s, field.c_str(), G_TYPE_UINT64, count, nullptr);
  }
  return s;
}

static void gst_marvelmind_positions_set_property(GObject* object, guint id, const GValue* value,
                                                  GParamSpec* pspec) {
  auto* self = GST_MARVELMIND_POSITIONS(object);
  gst::GLibLocker lock(self);
  if (self->state->running) {
    // As other sources do: what the client was started with stays until it stops.
    g_warning("marvelmindpositions: %s cannot change while running", pspec->name);
    return;
  }
  auto& c = self->state->config;
  switch (id) {
    case PROP_HOST:
      c.host = g_value_get_string(value) ? g_value_get_string(value) : "";
      break;
    case PROP_PORT:
      c.port = static_cast<uint16_t>(g_value_get_uint(value));
      break;
    case PROP_BEACONS: {
      const char* text = g_value_get_string(value);
      auto beacons = mm::parseBeacons(text ? text : "");
      if (!beacons) {
        g_warning("marvelmindpositions: beacons: %s", beacons.error().c_str());
        break;
      }
      c.beacons = *beacons;
      break;
    }
    case PROP_MODE:
      c.mode = static_cast<mm::Mode>(g_value_get_enum(value));
      break;
    case PROP_LISTEN_PORT:
      c.listenPort = static_cast<uint16_t>(g_value_get_uint(value));
      break;
    case PROP_POLL_RATE:
      c.pollRate = g_value_get_double(value);
      break;
    case PROP_UNITS:
      c.resolution = static_cast<mm::Resolution>(g_value_get_enum(value));
      break;
    case PROP_TIMESTAMP_UNIT:
      c.timestampUnit = static_cast<mm::TimestampUnit>(g_value_get_enum(value));
      break;
    case PROP_STALE_TIMEOUT:
      c.staleAfter = std::chrono::milliseconds(g_value_get_uint(value));
      break;
    default:
      G_OBJECT_WARN_INVALID_PROPERTY_ID(object, id, pspec);
  }
}

static void gst_marvelmind_positions_get_property(GObject* object, guint id, GValue* value,
                                                  GParamSpec* pspec) {
  auto* self = GST_MARVELMIND_POSITIONS(object);
  if (id == PROP_STATS) {
    g_value_take_boxed(value, stats_structure(self));
    return;
  }
  gst::GLibLocker lock(self);
  const auto& c = self->state->config;
  switch (id) {
    case PROP_HOST:
      g_value_set_string(value, c.host.c_str());
      break;
    case PROP_PORT:
      g_value_set_uint(value, c.port);
      break;
    case PROP_BEACONS:
      g_value_set_string(value, beaconList(c.beacons).c_str());
      break;
    case PROP_MODE:
      g_value_set_enum(value, static_cast<gint>(c.mode));
      break;
    case PROP_LISTEN_PORT:
      g_value_set_uint(value, c.listenPort);
      break;
    case PROP_POLL_RATE:
      g_value_set_double(value, c.pollRate);
      break;
    case PROP_UNITS:
      g_value_set_enum(value, static_cast<gint>(c.resolution));
      break;
    case PROP_TIMESTAMP_UNIT:
      g_value_set_enum(value, static_cast<gint>(c.timestampUnit));
      break;
    case PROP_STALE_TIMEOUT:
      g_value_set_uint(value, static_cast<guint>(c.staleAfter.count()));
      break;
    default:
      G_OBJECT_WARN_INVALID_PROPERTY_ID(object, id, pspec);
  }
}

static void gst_marvelmind_positions_finalize(GObject* object) {
  delete GST_MARVELMIND_POSITIONS(object)->state;
  G_OBJECT_CLASS(gst_marvelmind_positions_parent_class)->finalize(object);
}

static void gst_marvelmind_positions_class_init(GstMarvelmindPositionsClass* klass) {
  GST_DEBUG_CATEGORY_INIT(marvelmind_positions_debug, "marvelmindpositions", 0,
                          "Marvelmind positions");
  auto* gobject = G_OBJECT_CLASS(klass);
  gobject->set_property = gst_marvelmind_positions_set_property;
  gobject->get_property = gst_marvelmind_positions_get_property;
  gobject->finalize = gst_marvelmind_positions_finalize;
  auto flags = static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS);
  g_object_class_install_property(
      gobject, PROP_HOST,
      g_param_spec_string("host", "Dashboard host",
                          "Address of the computer running the Marvelmind dashboard (stream "
                          "mode: only its datagrams are taken; empty takes anyone's)",
                          DEFAULT_HOST, flags));
  g_object_class_install_property(
      gobject, PROP_PORT,
      g_param_spec_uint("port", "Dashboard port",
                        "The dashboard's UDP port (File/Parameters in the dashboard)", 1, 65535,
                        mm::kDefaultDashboardPort, flags));
  g_object_class_install_property(
      gobject, PROP_BEACONS,
      g_param_spec_string("beacons", "Beacons",
                          "Addresses of the vehicle's mobile beacons (hedgehogs), e.g. 5 or 5,6",
                          DEFAULT_BEACONS, flags));
  g_object_class_install_property(
      gobject, PROP_MODE,
      g_param_spec_enum("mode", "Mode", "Poll the dashboard, or take what it pushes", modeType(),
                        static_cast<gint>(mm::Mode::kPoll), flags));
  g_object_class_install_property(
      gobject, PROP_LISTEN_PORT,
      g_param_spec_uint("listen-port", "Listen port",
                        "Stream mode: the UDP port the dashboard pushes to (client libraries "
                        "use 49100; 0 = any free one)",
                        0, 65535, 0, flags));
  g_object_class_install_property(
      gobject, PROP_POLL_RATE,
      g_param_spec_double("poll-rate", "Poll rate",
                          "Requests per second per beacon in poll mode; a position is at most "
                          "about 1/poll-rate older than the frame it is joined to",
                          0.5, 100, DEFAULT_POLL_RATE, flags));
  g_object_class_install_property(
      gobject, PROP_UNITS,
      g_param_spec_enum("units", "Units", "Coordinates to ask for", unitsType(),
                        static_cast<gint>(mm::Resolution::kCentimetres), flags));
  g_object_class_install_property(
      gobject, PROP_TIMESTAMP_UNIT,
      g_param_spec_enum("timestamp-unit", "Timestamp unit",
                        "Unit of the dashboard's timestamps: 1/64 s per the protocol text, "
                        "milliseconds on newer dashboards",
                        timestampUnitType(), static_cast<gint>(mm::TimestampUnit::kSixtyFourths),
                        flags));
  g_object_class_install_property(
      gobject, PROP_STALE_TIMEOUT,
      g_param_spec_uint("stale-timeout", "Stale timeout",
                        "ms without a new position after which a beacon is stale "
                        "(marvelmind-stale is posted and it is no longer joined to frames)",
                        100, 600000, DEFAULT_STALE_TIMEOUT, flags));
  g_object_class_install_property(
      gobject, PROP_STATS,
      g_param_spec_boxed("stats", "Statistics",
                         "requests, replies, positions (new measurements), repeats (the same "
                         "one again), rejected (with rejected-<reason> per reason), foreign",
                         GST_TYPE_STRUCTURE,
                         static_cast<GParamFlags>(G_PARAM_READABLE | G_PARAM_STATIC_STRINGS)));

  auto* element = GST_ELEMENT_CLASS(klass);
  gst_element_class_add_static_pad_template(element, &sink_template);
  gst_element_class_add_static_pad_template(element, &src_template);
  gst_element_class_set_static_metadata(
      element, "Marvelmind positions", "Filter/Metadata",
      "Joins Marvelmind indoor positions to the video as WircPositionMeta and bus messages",
      "wircam");
  auto* transform = GST_BASE_TRANSFORM_CLASS(klass);
  transform->start = gst_marvelmind_positions_start;
  transform->stop = gst_marvelmind_positions_stop;
  transform->transform_ip = gst_marvelmind_positions_transform_ip;
  transform->passthrough_on_same_caps = FALSE;
  gst_type_mark_as_plugin_api(modeType(), GstPluginAPIFlags(0));
  gst_type_mark_as_plugin_api(unitsType(), GstPluginAPIFlags(0));
  gst_type_mark_as_plugin_api(timestampUnitType(), GstPluginAPIFlags(0));
}

static void gst_marvelmind_positions_init(GstMarvelmindPositions* self) {
  self->state = new PositionsState();
  self->state->config.host = DEFAULT_HOST;
  self->state->config.beacons = {5};
  gst_base_transform_set_in_place(GST_BASE_TRANSFORM(self), TRUE);
}
