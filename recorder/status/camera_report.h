// What the recorder shows of one camera, as plain data, and the forms it
// takes: an entry of /api/status, of /api/cameras, the MQTT status, the
// status line. GStreamer-free: the camera fills it in.
#pragma once

#include <cstdint>
#include <deque>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

namespace wircam::recorder {

// The vehicle's latest Marvelmind position.
struct Position {
  unsigned beacon = 0;
  double x = 0, y = 0, z = 0;
  int64_t unixMs = 0;
};

// What the camera's wirccontrol says, when it steers a vehicle.
struct ControlReport {
  bool hasControl = false, following = false;
  int target = -1;
};

struct CameraReport {
  std::string name;    // "<device>-cam<N>"
  std::string device;  // the device's label
  int camera = 0;
  std::string state;  // connecting, live, no-video, offline
  int64_t stateSinceUnixMs = 0;
  bool everLive = false;       // logged in at least once (else: waiting for the device)
  std::string linkReason;      // why the link is not live, while it is not
  unsigned restarts = 0;       // of its pipeline, after faults
  uint64_t deadManLapses = 0;  // drive mode: the page fell silent, the vehicle went to neutral
  // The source's figures, from its last wirc-stats.
  uint64_t frames = 0, incomplete = 0, bytes = 0;
  uint64_t commandsSent = 0;  // PCD to the WiRC vehicle, keepalives included
  // Frames received but not recorded: what waited for the camera's disk
  // had reached its bound (a slow or stalled disk).
  uint64_t recordingDropped = 0;
  double fps = 0, kbps = 0;
  unsigned batteryMv = 0;
  bool statusStale = false;  // the device stopped reporting; batteryMv is its last word
  uint64_t statusAgeMs = 0;
  std::string segment;                   // the file being written (a path), or empty
  std::optional<ControlReport> control;  // with --follow, on the steering camera
  bool positions = false;                // with --marvelmind
  std::optional<Position> position;
  std::string positionStale;  // why, when no position came for a while
};

// The share of frames lost, in percent.
double lossPercent(const CameraReport& camera);
// The latest position for status and MQTT: null until one came.
nlohmann::json positionJson(const CameraReport& camera);
// One entry of /api/status's "streams" (`rtsp`: its RTSP address, or empty).
nlohmann::json statusJson(const CameraReport& camera, const std::string& rtsp);
// One entry of /api/cameras.
nlohmann::json cameraJson(const CameraReport& camera);
// The retained MQTT status of PREFIX/STREAM/status.
nlohmann::json fleetStatusJson(const CameraReport& camera);
// The points of the live view's map.
nlohmann::json trailJson(const std::deque<Position>& trail, bool stale);
// The status line printed every --status seconds (no newline).
std::string statusLine(const CameraReport& camera);

}  // namespace wircam::recorder
