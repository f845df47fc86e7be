#include "status/prometheus_metrics.h"

#include <glib.h>

#include <functional>

namespace wircam::recorder {

namespace {

// The camera states /api/cameras names; one 0/1 series each.
constexpr const char* kStates[] = {"connecting", "live", "no-video", "offline"};

// Nine digits: more than a volt or a frame rate means, and no float noise.
std::string number(double value) {
  char text[G_ASCII_DTOSTR_BUF_SIZE];
  return g_ascii_formatd(text, sizeof text, "%.9g", value);
}

// One family after another: its HELP and TYPE lines, then its samples.
class Exposition {
 public:
  void family(const char* name, const char* type, const char* help) {
    name_ = name;
    text_ += std::string("# HELP ") + name + " " + help + "\n# TYPE " + name + " " + type + "\n";
  }
  void sample(const std::string& labels, double value) {
    text_ += name_ + (labels.empty() ? "" : "{" + labels + "}") + " " + number(value) + "\n";
  }
  void sample(const std::string& labels, uint64_t value) {
    text_ +=
        name_ + (labels.empty() ? "" : "{" + labels + "}") + " " + std::to_string(value) + "\n";
  }
  // Per camera, the family's value (or nothing to leave the camera out).
  template <typename Value>
  void perCamera(const std::vector<CameraReport>& cameras,
                 const std::function<std::optional<Value>(const CameraReport&)>& value) {
    for (const auto& camera : cameras)
      if (auto v = value(camera)) sample("stream=\"" + escapedLabel(camera.name) + "\"", *v);
  }
  const std::string& text() const { return text_; }

 private:
  std::string text_, name_;
};

}  // namespace

std::string escapedLabel(const std::string& value) {
  std::string escaped;
  for (char c : value) {
    if (c == '\\' || c == '"') escaped += '\\';
    if (c == '\n') {
      escaped += "\\n";
      continue;
    }
    escaped += c;
  }
  return escaped;
}

std::string prometheusText(const RecorderMetrics& m) {
  Exposition out;
  using Report = const CameraReport&;
  out.family("wircam_build_info", "gauge", "The recorder's version, as a label; always 1.");
  out.sample("version=\"" + escapedLabel(m.version) + "\"", uint64_t{1});

  out.family("wircam_frames_received_total", "counter",
             "Whole frames the camera's source assembled from the device's packets.");
  out.perCamera<uint64_t>(m.cameras, [](Report c) { return c.frames; });
  out.family("wircam_frames_incomplete_total", "counter",
             "Frames lost because packets of them never came (the stream's loss).");
  out.perCamera<uint64_t>(m.cameras, [](Report c) { return c.incomplete; });
  out.family("wircam_recording_dropped_frames_total", "counter",
             "Frames received but not recorded: the camera's bytes waiting for its disk "
             "had reached --record-queue (a slow or stalled disk).");
  out.perCamera<uint64_t>(m.cameras, [](Report c) { return c.recordingDropped; });
  out.family("wircam_received_bytes_total", "counter", "JPEG bytes received from the device.");
  out.perCamera<uint64_t>(m.cameras, [](Report c) { return c.bytes; });

  auto recorded = [&](uint64_t RecordedTotals::*field) {
    return [&m, field](Report c) -> std::optional<uint64_t> {
      auto it = m.recorded.find(c.name);
      return it == m.recorded.end() ? 0 : it->second.*field;
    };
  };
  const struct {
    const char* name;
    const char* help;
    uint64_t RecordedTotals::*field;
  } kRecordedCounters[] = {
      {"wircam_frames_recorded_total", "Frames in the segments closed since the recorder started.",
       &RecordedTotals::frames},
      {"wircam_segments_closed_total", "Segments finished and indexed since the recorder started.",
       &RecordedTotals::segmentsClosed},
      {"wircam_recorded_bytes_total", "Bytes of the segments closed since the recorder started.",
       &RecordedTotals::bytes},
      {"wircam_hook_failures_total",
       "Runs of the --on-segment-closed hook that failed or timed out.",
       &RecordedTotals::hookFailures},
  };
  for (const auto& counter : kRecordedCounters) {
    out.family(counter.name, "counter", counter.help);
    out.perCamera<uint64_t>(m.cameras, recorded(counter.field));
  }

  out.family("wircam_stream_up", "gauge", "1 while the camera's frames arrive (state live).");
  out.perCamera<uint64_t>(m.cameras, [](Report c) { return uint64_t{c.state == "live"}; });
  out.family("wircam_link_up", "gauge",
             "1 while the recorder is logged in to the camera's device (live or no-video).");
  out.perCamera<uint64_t>(
      m.cameras, [](Report c) { return uint64_t{c.state == "live" || c.state == "no-video"}; });
  out.family("wircam_camera_state", "gauge", "1 for the camera's current state, 0 for the others.");
  for (const auto& camera : m.cameras)
    for (const char* state : kStates)
      out.sample("stream=\"" + escapedLabel(camera.name) + "\",state=\"" + state + "\"",
                 uint64_t{camera.state == state});
  out.family("wircam_camera_restarts_total", "counter",
             "Times the camera's pipeline was started again after a fault.");
  out.perCamera<uint64_t>(m.cameras, [](Report c) { return uint64_t{c.restarts}; });
  out.family("wircam_pcd_sent_total", "counter",
             "Commands (PCD) the camera's link sent to the WiRC vehicle, keepalives included.");
  out.perCamera<uint64_t>(m.cameras, [](Report c) { return c.commandsSent; });
  out.family("wircam_drive_deadman_lapses_total", "counter",
             "Times drive mode's dead-man put the vehicle at neutral (the page fell silent).");
  out.perCamera<uint64_t>(m.cameras, [](Report c) { return c.deadManLapses; });
  out.family("wircam_frames_per_second", "gauge", "The camera's frame rate of late.");
  out.perCamera<double>(m.cameras, [](Report c) { return c.fps; });
  out.family("wircam_battery_volts", "gauge", "The vehicle's battery as its device last reported.");
  out.perCamera<double>(m.cameras, [](Report c) -> std::optional<double> {
    if (c.batteryMv == 0) return std::nullopt;
    return c.batteryMv / 1000.0;
  });
  out.family("wircam_has_control", "gauge",
             "1 while the recorder holds the vehicle's control right (cameras that steer).");
  out.perCamera<uint64_t>(m.cameras, [](Report c) -> std::optional<uint64_t> {
    if (!c.control) return std::nullopt;
    return uint64_t{c.control->hasControl};
  });

  out.family("wircam_disk_free_bytes", "gauge", "Free space where the recordings go.");
  out.sample("", m.diskFreeBytes);
  out.family("wircam_http_connections", "gauge", "Connections open to the web server.");
  out.sample("", m.httpConnections);
  if (m.foxglove) {
    out.family("wircam_foxglove_clients", "gauge", "Foxglove WebSocket clients connected.");
    out.sample("", m.foxglove->clients);
    out.family("wircam_foxglove_refused_total", "counter",
               "Foxglove clients refused: as many as --foxglove-max-clients were connected.");
    out.sample("", m.foxglove->refused);
    out.family("wircam_foxglove_sent_total", "counter", "Messages sent to Foxglove clients.");
    out.sample("", m.foxglove->sent);
    out.family("wircam_foxglove_dropped_total", "counter",
               "Messages a slow Foxglove client had no room for (dropped, never queued).");
    out.sample("", m.foxglove->dropped);
  }
  if (m.mqttConnected) {
    out.family("wircam_mqtt_connected", "gauge", "1 while the MQTT broker is connected.");
    out.sample("", uint64_t{*m.mqttConnected});
    out.family("wircam_mqtt_published_total", "counter", "MQTT messages handed to the broker.");
    out.sample("", m.mqttPublished.value_or(0));
    out.family("wircam_mqtt_dropped_total", "counter",
               "MQTT messages dropped (the broker away or too slow).");
    out.sample("", m.mqttDropped.value_or(0));
  }
  return out.text();
}

}  // namespace wircam::recorder
