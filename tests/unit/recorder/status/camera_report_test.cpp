// What the recorder shows of a camera: the /api/cameras entry word for word,
// the MQTT status, the status line.
#include "status/camera_report.h"

#include <gtest/gtest.h>

namespace wircam::recorder {
namespace {

CameraReport liveCamera() {
  CameraReport camera;
  camera.name = "rover-cam0";
  camera.device = "rover";
  camera.state = "live";
  camera.everLive = true;
  camera.frames = 297;
  camera.incomplete = 3;
  camera.fps = 14.96;
  camera.kbps = 812;
  camera.batteryMv = 7400;
  camera.segment = "/data/rec/rover-cam0/2026-11-24T10-00-00Z.mkv";
  return camera;
}

TEST(CameraReport, TheCamerasEntryHoldsExactlyItsNameStateRateAndControl) {
  auto camera = liveCamera();
  EXPECT_EQ(cameraJson(camera), nlohmann::json::parse(R"({"name":"rover-cam0","state":"live",
      "fps":15.0,"has_control":false,"following":false})"));
  camera.state = "no-video";
  camera.control = ControlReport{true, true, 3};
  auto json = cameraJson(camera);
  EXPECT_EQ(json["state"], "no-video");
  EXPECT_EQ(json["has_control"], true);
  EXPECT_EQ(json["following"], true);
}

TEST(CameraReport, LossIsTheShareOfIncompleteFramesAndNothingBeforeTheFirst) {
  auto camera = liveCamera();
  EXPECT_DOUBLE_EQ(lossPercent(camera), 1.0);
  EXPECT_DOUBLE_EQ(lossPercent(CameraReport{}), 0.0);
  EXPECT_DOUBLE_EQ(fleetStatusJson(camera)["loss"].get<double>(), 1.0);
}

TEST(CameraReport, APositionIsNullUntilOneCameAndSaysWhyWhenStale) {
  auto camera = liveCamera();
  camera.positions = true;
  EXPECT_TRUE(positionJson(camera).is_null());
  camera.positionStale = "no position for 3 s";
  EXPECT_EQ(positionJson(camera)["stale"], true);
  EXPECT_EQ(positionJson(camera)["stale_reason"], "no position for 3 s");
  camera.position = Position{6, 1.25, -0.5, 0, 0};
  auto position = statusJson(camera, "")["position"];
  EXPECT_EQ(position["beacon"], 6);
  EXPECT_EQ(position["x"], 1.25);
  EXPECT_EQ(position["utc"], "1970-01-01T00:00:00.000Z");
}

TEST(CameraReport, TheStatusEntryNamesTheFileNotItsFolderAndTheRtspAddressWhenServed) {
  auto camera = liveCamera();
  auto json = statusJson(camera, "");
  EXPECT_EQ(json["segment"], "2026-11-24T10-00-00Z.mkv");
  EXPECT_EQ(json["live"], "/live/rover-cam0.mjpg");
  EXPECT_FALSE(json.contains("rtsp"));
  EXPECT_FALSE(json.contains("position"));
  EXPECT_EQ(statusJson(camera, "rtsp://h:8554/rover-cam0")["rtsp"], "rtsp://h:8554/rover-cam0");
}

TEST(CameraReport, TheStatusLineWaitsForADeviceAndMarksAStaleBatteryAndAFault) {
  CameraReport waiting;
  waiting.name = "rover-cam0";
  waiting.state = "connecting";
  EXPECT_NE(statusLine(waiting).find("waiting for device"), std::string::npos);
  auto camera = liveCamera();
  EXPECT_EQ(statusLine(camera).find('['), std::string::npos);
  camera.statusStale = true;
  camera.statusAgeMs = 4200;
  camera.state = "offline";
  auto line = statusLine(camera);
  EXPECT_NE(line.find("7.40 V (stale, 4 s old)"), std::string::npos) << line;
  EXPECT_NE(line.find("[offline]"), std::string::npos) << line;
}

}  // namespace
}  // namespace wircam::recorder
