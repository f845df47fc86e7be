// /metrics' text: families, labels as the format escapes them, and the
// series a camera without a vehicle to steer leaves out.
#include "status/prometheus_metrics.h"

#include <gtest/gtest.h>

namespace wircam::recorder {
namespace {

TEST(PrometheusMetrics, EachCameraIsAStreamLabelAndItsStateOneSeriesPerState) {
  RecorderMetrics m;
  m.version = "0.1.0";
  CameraReport steering;
  steering.name = "rover-cam0";
  steering.state = "no-video";
  steering.frames = 120;
  steering.batteryMv = 7400;
  steering.control = ControlReport{.hasControl = true};
  steering.deadManLapses = 2;
  steering.commandsSent = 300;
  CameraReport quiet;
  quiet.name = "odd\"name\\x";
  quiet.state = "offline";
  m.cameras = {steering, quiet};
  m.recorded["rover-cam0"] = {.segmentsClosed = 2, .bytes = 5000, .frames = 110};
  m.diskFreeBytes = 1234;
  auto text = prometheusText(m);
  for (const char* line : {
           "wircam_build_info{version=\"0.1.0\"} 1\n",
           "wircam_frames_received_total{stream=\"rover-cam0\"} 120\n",
           "wircam_frames_recorded_total{stream=\"rover-cam0\"} 110\n",
           "wircam_segments_closed_total{stream=\"rover-cam0\"} 2\n",
           "wircam_stream_up{stream=\"rover-cam0\"} 0\n",
           "wircam_link_up{stream=\"rover-cam0\"} 1\n",
           "wircam_camera_state{stream=\"rover-cam0\",state=\"no-video\"} 1\n",
           "wircam_camera_state{stream=\"rover-cam0\",state=\"live\"} 0\n",
           "wircam_battery_volts{stream=\"rover-cam0\"} 7.4\n",
           "wircam_has_control{stream=\"rover-cam0\"} 1\n",
           "wircam_drive_deadman_lapses_total{stream=\"rover-cam0\"} 2\n",
           "wircam_pcd_sent_total{stream=\"rover-cam0\"} 300\n",
           "wircam_segments_closed_total{stream=\"odd\\\"name\\\\x\"} 0\n",
           "wircam_disk_free_bytes 1234\n",
       })
    EXPECT_NE(text.find(line), std::string::npos) << line << "\n" << text;
  // No battery report, no vehicle to steer, no MQTT: no series for them.
  EXPECT_EQ(text.find("wircam_battery_volts{stream=\"odd"), std::string::npos);
  EXPECT_EQ(text.find("wircam_has_control{stream=\"odd"), std::string::npos);
  EXPECT_EQ(text.find("wircam_mqtt"), std::string::npos);
}

TEST(PrometheusMetrics, LabelValuesAreEscaped) {
  EXPECT_EQ(escapedLabel("a\"b\\c\nd"), "a\\\"b\\\\c\\nd");
}

}  // namespace
}  // namespace wircam::recorder
