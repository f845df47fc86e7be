// The element messages wircam's elements post on the bus, as typed schemas:
// each message's name and a reader of its fields, in one place for the
// elements that post them and the applications (wirc-recorder among them)
// that read them. Header-only C++17; C and Python read the same names and
// fields with gst_structure_get_*() (gst-inspect-1.0 lists them per element).
#pragma once

#include <gst/gst.h>

#include <cstdint>
#include <optional>
#include <string>

namespace wircam::bus {

namespace detail {
inline std::string text(const GstStructure* s, const char* field) {
  const char* value = gst_structure_get_string(s, field);
  return value ? value : "";
}
inline std::optional<std::string> optionalText(const GstStructure* s, const char* field) {
  const char* value = gst_structure_get_string(s, field);
  if (!value) return std::nullopt;
  return std::string(value);
}
}  // namespace detail

// wircsrc: an event of the device's link (a loss, a login, the control
// right, a refusal); `state` and `reason` when the link's state changed.
struct Session {
  static constexpr const char* kName = "wirc-session";
  std::string event;
  std::optional<std::string> state;  // "live", "connecting", "lost"...
  std::string reason;
  static Session read(const GstStructure* s) {
    return {detail::text(s, "event"), detail::optionalText(s, "state"), detail::text(s, "reason")};
  }
};

// wircsrc and wircdepay, every stats-interval: the stream's counters and
// the device's status.
struct Stats {
  static constexpr const char* kName = "wirc-stats";
  guint64 framesComplete = 0, framesIncomplete = 0, bytes = 0;
  guint64 commandsSent = 0;  // PCD the vehicle link sent, keepalives included
  guint batteryMv = 0;
  bool statusStale = false;  // the device stopped reporting; batteryMv is its last word
  guint64 statusAgeMs = 0;
  static Stats read(const GstStructure* s) {
    Stats stats;
    gboolean stale = FALSE;
    gst_structure_get_uint64(s, "frames-complete", &stats.framesComplete);
    gst_structure_get_uint64(s, "frames-incomplete", &stats.framesIncomplete);
    gst_structure_get_uint64(s, "bytes", &stats.bytes);
    gst_structure_get_uint64(s, "commands-sent", &stats.commandsSent);
    gst_structure_get_uint(s, "battery-mv", &stats.batteryMv);
    gst_structure_get_boolean(s, "status-stale", &stale);
    gst_structure_get_uint64(s, "status-age-ms", &stats.statusAgeMs);
    stats.statusStale = stale != FALSE;
    return stats;
  }
};

// wirccontrol: the steered vehicle's link (RCOIP, BTEMP or WiRC) and its
// status reports; `state` only when the link changed.
struct Vehicle {
  static constexpr const char* kName = "wirc-vehicle";
  std::string event;
  std::optional<std::string> state;
  static Vehicle read(const GstStructure* s) {
    return {detail::text(s, "event"), detail::optionalText(s, "state")};
  }
};

// wirccontrol: the control right was won or lost.
struct ControlRight {
  static constexpr const char* kName = "wirc-control-right";
};

// wirccontrol: a command it sent for a frame's detections (`timestamp`: the
// frame's PTS).
struct Control {
  static constexpr const char* kName = "wirc-control";
};

// wirccontrol: a command driven by hand, or the dead-man's neutral.
struct Drive {
  static constexpr const char* kName = "wirc-drive";
};

// apriltagdetect: a frame's detections (`timestamp`: the frame's PTS).
struct AprilTags {
  static constexpr const char* kName = "apriltag";
};

// The PTS of the frame a message belongs to (AprilTags, Control).
inline GstClockTime frameTimestamp(const GstStructure* s) {
  guint64 pts = GST_CLOCK_TIME_NONE;
  gst_structure_get_uint64(s, "timestamp", &pts);
  return pts;
}

// marvelmindpositions: a beacon's position, measured at `runningTime`
// (none for a position from before PLAYING).
struct Position {
  static constexpr const char* kName = "marvelmind-position";
  guint beacon = 0;
  double x = 0, y = 0, z = 0;
  GstClockTime runningTime = GST_CLOCK_TIME_NONE;
  static Position read(const GstStructure* s) {
    Position p;
    guint64 measured = GST_CLOCK_TIME_NONE;
    gst_structure_get_uint(s, "beacon", &p.beacon);
    gst_structure_get_double(s, "x", &p.x);
    gst_structure_get_double(s, "y", &p.y);
    gst_structure_get_double(s, "z", &p.z);
    gst_structure_get_uint64(s, "running-time", &measured);
    p.runningTime = measured;
    return p;
  }
};

// marvelmindpositions: no position of a beacon for a while, and why.
struct PositionStale {
  static constexpr const char* kName = "marvelmind-stale";
  guint beacon = 0;
  std::string reason;
  static PositionStale read(const GstStructure* s) {
    PositionStale stale;
    gst_structure_get_uint(s, "beacon", &stale.beacon);
    stale.reason = detail::text(s, "reason");
    return stale;
  }
};

// Whether `s` is the message `Schema`.
template <typename Schema>
bool is(const GstStructure* s) {
  return s && gst_structure_has_name(s, Schema::kName);
}

}  // namespace wircam::bus
