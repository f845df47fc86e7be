/**
 * SECTION:element-wircdepay
 *
 * Reassembles the WiRC MJPEG-over-UDP packets, one UDP payload per input
 * buffer, into whole JPEG frames: for captures, or when another application
 * holds the device's control connection. Same assembler and counters as
 * wircsrc, posted as a `wirc-stats` element message every `stats-interval`
 * of the datagrams' time; it never pushes a corrupt or partial frame. The device sends
 * datagrams of up to 64 KB, so give udpsrc a large enough buffer and mtu.
 *
 * ## Example launch line
 * |[
 * gst-launch-1.0 udpsrc port=5000 buffer-size=8388608 mtu=65536 caps=application/x-wirc-mjpeg ! wircdepay ! jpegdec ! videoconvert ! autovideosink
 * ]|
 */
#include "gstwircdepay.h"

#include <memory>
#include <mutex>
#include <optional>

#include "common/mutex.h"
#include "frame_buffers.h"
#include "gst_scoped.h"
#include "wirc/frame_assembler.h"

GST_DEBUG_CATEGORY_STATIC(wirc_depay_debug);
#define GST_CAT_DEFAULT wirc_depay_debug

namespace {

using namespace wircam;
using Clock = std::chrono::steady_clock;

#define DEFAULT_FRAME_TIMEOUT 200
#define DEFAULT_STATS_INTERVAL 1000  // as wircsrc's

enum { PROP_0, PROP_FRAME_TIMEOUT, PROP_STATS_INTERVAL, PROP_STATS };

struct WircDepayState {
  guint frameTimeoutMs = DEFAULT_FRAME_TIMEOUT;     // guarded by the object lock
  guint statsIntervalMs = DEFAULT_STATS_INTERVAL;   // guarded by the object lock
  std::optional<Clock::time_point> nextStats;       // streaming thread only
  std::unique_ptr<wirc::FrameAssembler> assembler;  // streaming thread only
  int width = 0;
  int height = 0;
  // Held back until the first frame's caps are out: sticky events must go
  // caps before segment.
  GstEvent* pendingSegment = nullptr;
  Mutex statsMutex;  // the stats property reads stats
  wirc::AssemblerStats stats WIRCAM_GUARDED_BY(statsMutex);
};

}  // namespace

struct _GstWircDepay {
  GstElement parent;
  GstPad* sinkpad;
  GstPad* srcpad;
  WircDepayState* state;
};

G_DEFINE_TYPE(GstWircDepay, gst_wirc_depay, GST_TYPE_ELEMENT)

static GstStaticPadTemplate sink_template = GST_STATIC_PAD_TEMPLATE(
    "sink", GST_PAD_SINK, GST_PAD_ALWAYS, GST_STATIC_CAPS("application/x-wirc-mjpeg"));
static GstStaticPadTemplate src_template =
    GST_STATIC_PAD_TEMPLATE("src", GST_PAD_SRC, GST_PAD_ALWAYS, GST_STATIC_CAPS("image/jpeg"));

static wirc::FrameAssembler& assembler_of(GstWircDepay* self) {
  auto* state = self->state;
  if (!state->assembler) {
    guint timeout;
    {
      gst::GLibLocker lock(self);
      timeout = state->frameTimeoutMs;
    }
    state->assembler = std::make_unique<wirc::FrameAssembler>(
        wirc::FrameAssemblerConfig{.frameTimeout = std::chrono::milliseconds(timeout)});
  }
  return *state->assembler;
}

// Time as the assembler counts it: the datagram's timestamp (udpsrc's
// arrival time), or the pipeline clock's now for one without. So the
// frame-timeout runs on the stream's time, and a test clock drives it.
static Clock::time_point arrival_time(GstWircDepay* self, GstBuffer* buffer) {
  GstClockTime time = GST_BUFFER_PTS(buffer);
  if (!GST_CLOCK_TIME_IS_VALID(time)) {
    GstClock* clock = gst_element_get_clock(GST_ELEMENT(self));
    if (!clock) clock = gst_system_clock_obtain();
    time = gst_clock_get_time(clock);
    gst_object_unref(clock);
  }
  return Clock::time_point(std::chrono::nanoseconds(time));
}

static GstFlowReturn push_frames(GstWircDepay* self, std::vector<wirc::AssembledFrame>& frames,
                                 bool stamped) {
  auto* state = self->state;
  GstFlowReturn result = GST_FLOW_OK;
  for (auto& frame : frames) {
    // Stamped like the datagram that started it.
    auto firstPacket =
        static_cast<GstClockTime>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                      frame.firstPacketTime.time_since_epoch())
                                      .count());
    bool discont = frame.discont;
    GstBuffer* buffer = gst::wrapFrame(std::move(frame));
    if (stamped) GST_BUFFER_PTS(buffer) = firstPacket;
    if (discont) GST_BUFFER_FLAG_SET(buffer, GST_BUFFER_FLAG_DISCONT);
    if (GstCaps* caps = gst::jpegCapsIfChanged(buffer, state->width, state->height)) {
      gst_pad_push_event(self->srcpad, gst_event_new_caps(caps));
      gst_caps_unref(caps);
    }
    if (state->pendingSegment) {
      gst_pad_push_event(self->srcpad, state->pendingSegment);
      state->pendingSegment = nullptr;
    }
    if (result == GST_FLOW_OK)
      result = gst_pad_push(self->srcpad, buffer);
    else
      gst_buffer_unref(buffer);
  }
  frames.clear();
  return result;
}

// The counters as a "wirc-stats" element message every stats-interval of
// the datagrams' time (the clock's when they carry none), as wircsrc posts
// them; the first one interval after the first datagram.
static void post_stats_when_due(GstWircDepay* self, Clock::time_point now) {
  guint intervalMs;
  {
    gst::GLibLocker lock(self);
    intervalMs = self->state->statsIntervalMs;
  }
  auto& next = self->state->nextStats;
  if (intervalMs == 0) return next.reset();
  if (!next) next = now + std::chrono::milliseconds(intervalMs);
  if (now < *next) return;
  next = now + std::chrono::milliseconds(intervalMs);
  GstStructure* stats;
  {
    MutexLock lock(self->state->statsMutex);
    stats = gst::statsStructure(self->state->stats, 0);
  }
  gst_element_post_message(GST_ELEMENT(self), gst_message_new_element(GST_OBJECT(self), stats));
}

static GstFlowReturn gst_wirc_depay_chain(GstPad*, GstObject* parent, GstBuffer* buffer) {
  auto* self = GST_WIRC_DEPAY(parent);
  auto& assembler = assembler_of(self);
  std::vector<wirc::AssembledFrame> frames;
  auto collect = [&](wirc::AssembledFrame&& frame) { frames.push_back(std::move(frame)); };
  auto now = arrival_time(self, buffer);
  if (gst::ScopedBufferMap map(buffer, GST_MAP_READ); map)
    assembler.pushDatagram({map.data(), map.size()}, now, collect);
  assembler.expire(now, collect);
  {
    MutexLock lock(self->state->statsMutex);
    self->state->stats = assembler.stats();
  }
  post_stats_when_due(self, now);
  bool stamped = GST_BUFFER_PTS_IS_VALID(buffer);
  gst_buffer_unref(buffer);
  return push_frames(self, frames, stamped);
}

static gboolean gst_wirc_depay_sink_event(GstPad* pad, GstObject* parent, GstEvent* event) {
  auto* self = GST_WIRC_DEPAY(parent);
  switch (GST_EVENT_TYPE(event)) {
    case GST_EVENT_CAPS:
      // Output caps come from the frames' SOF markers.
      gst_event_unref(event);
      return TRUE;
    case GST_EVENT_SEGMENT:
      if (!gst_pad_has_current_caps(self->srcpad)) {
        gst_event_replace(&self->state->pendingSegment, event);
        gst_event_unref(event);
        return TRUE;
      }
      break;
    case GST_EVENT_FLUSH_STOP:
      if (self->state->assembler) self->state->assembler->reset();
      break;
    default:
      break;
  }
  return gst_pad_event_default(pad, parent, event);
}

static GstStateChangeReturn gst_wirc_depay_change_state(GstElement* element,
                                                        GstStateChange transition) {
  auto* self = GST_WIRC_DEPAY(element);
  auto result = GST_ELEMENT_CLASS(gst_wirc_depay_parent_class)->change_state(element, transition);
  if (transition == GST_STATE_CHANGE_PAUSED_TO_READY) {
    gst_event_replace(&self->state->pendingSegment, nullptr);
    self->state->assembler.reset();
    self->state->nextStats.reset();
    self->state->width = self->state->height = 0;
  }
  return result;
}

static void gst_wirc_depay_set_property(GObject* object, guint id, const GValue* value,
                                        GParamSpec* pspec) {
  auto* self = GST_WIRC_DEPAY(object);
  gst::GLibLocker lock(self);
  if (id == PROP_FRAME_TIMEOUT)
    self->state->frameTimeoutMs = g_value_get_uint(value);
  else if (id == PROP_STATS_INTERVAL)
    self->state->statsIntervalMs = g_value_get_uint(value);
  else
    G_OBJECT_WARN_INVALID_PROPERTY_ID(object, id, pspec);
}

static void gst_wirc_depay_get_property(GObject* object, guint id, GValue* value,
                                        GParamSpec* pspec) {
  auto* self = GST_WIRC_DEPAY(object);
  if (id == PROP_STATS) {
    MutexLock lock(self->state->statsMutex);
    g_value_take_boxed(value, gst::statsStructure(self->state->stats, 0));
  } else if (id == PROP_FRAME_TIMEOUT) {
    gst::GLibLocker lock(self);
    g_value_set_uint(value, self->state->frameTimeoutMs);
  } else if (id == PROP_STATS_INTERVAL) {
    gst::GLibLocker lock(self);
    g_value_set_uint(value, self->state->statsIntervalMs);
  } else {
    G_OBJECT_WARN_INVALID_PROPERTY_ID(object, id, pspec);
  }
}

static void gst_wirc_depay_finalize(GObject* object) {
  delete GST_WIRC_DEPAY(object)->state;
  G_OBJECT_CLASS(gst_wirc_depay_parent_class)->finalize(object);
}

static void gst_wirc_depay_init(GstWircDepay* self) {
  self->state = new WircDepayState();
  self->sinkpad = gst_pad_new_from_static_template(&sink_template, "sink");
  gst_pad_set_chain_function(self->sinkpad, gst_wirc_depay_chain);
  gst_pad_set_event_function(self->sinkpad, gst_wirc_depay_sink_event);
  gst_element_add_pad(GST_ELEMENT(self), self->sinkpad);
  self->srcpad = gst_pad_new_from_static_template(&src_template, "src");
  gst_pad_use_fixed_caps(self->srcpad);
  gst_element_add_pad(GST_ELEMENT(self), self->srcpad);
}

static void gst_wirc_depay_class_init(GstWircDepayClass* klass) {
  auto* gobject = G_OBJECT_CLASS(klass);
  auto* element = GST_ELEMENT_CLASS(klass);
  gobject->set_property = gst_wirc_depay_set_property;
  gobject->get_property = gst_wirc_depay_get_property;
  gobject->finalize = gst_wirc_depay_finalize;
  element->change_state = gst_wirc_depay_change_state;

  g_object_class_install_property(
      gobject, PROP_FRAME_TIMEOUT,
      g_param_spec_uint("frame-timeout", "Frame timeout",
                        "Milliseconds an incomplete frame may "
                        "wait for its missing packets before it is dropped",
                        10, 10000, DEFAULT_FRAME_TIMEOUT,
                        static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS |
                                                 GST_PARAM_MUTABLE_READY)));
  g_object_class_install_property(
      gobject, PROP_STATS_INTERVAL,
      g_param_spec_uint("stats-interval", "Stats interval",
                        "Milliseconds of the datagrams' time between wirc-stats element messages "
                        "(0 = none)",
                        0, 3600000, DEFAULT_STATS_INTERVAL,
                        static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS |
                                                 GST_PARAM_MUTABLE_PLAYING)));
  g_object_class_install_property(
      gobject, PROP_STATS,
      g_param_spec_boxed("stats", "Statistics",
                         "Counters: packets, bytes, frames-complete, "
                         "frames-incomplete, packets-duplicate, packets-invalid, ...",
                         GST_TYPE_STRUCTURE,
                         static_cast<GParamFlags>(G_PARAM_READABLE | G_PARAM_STATIC_STRINGS)));

  gst_element_class_add_static_pad_template(element, &sink_template);
  gst_element_class_add_static_pad_template(element, &src_template);
  gst_element_class_set_static_metadata(
      element, "WiRC MJPEG depayloader", "Codec/Depayloader/Network",
      "Reassembles WiRC MJPEG-over-UDP packets into whole JPEG frames", "wircam authors");
  GST_DEBUG_CATEGORY_INIT(wirc_depay_debug, "wircdepay", 0, "WiRC MJPEG depayloader");
}
