// wirc-export --fleet: a vehicle's segments in a time range, gathered from
// whichever recorders of a fleet hold them, into one local folder that the
// export then reads as a recorder's own. The recorders are those announced
// on the fleet's broker (docs/fleet.md); each online one is asked for the
// vehicle's recordings (GET /api/recordings?vehicle=), and each segment in
// the range is fetched with its sidecar over HTTP(S), a dropped connection
// resumed where it broke (a range request).
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "common/expected.h"
#include "fleet/mqtt_url.h"

namespace wircam::recorder {

struct FleetFetchRequest {
  MqttUrl broker;
  std::string vehicle;          // its serial or its name
  std::string camera = "cam0";  // which of its cameras
  std::optional<int64_t> start, end;
  std::string token;             // the recorders' --http-token, if they have one
  std::filesystem::path folder;  // made, and filled
};

struct FleetFetchReport {
  std::string camera;    // the segments' camera in the folder: "<vehicle>-cam<N>"
  size_t announced = 0;  // recorders on the broker, online or not
  size_t asked = 0;      // recorders that answered
  size_t holders = 0;    // of them, those that held segments in the range
  size_t segments = 0;
  uint64_t bytes = 0;
  std::vector<std::string> notes;  // recorders that were offline or did not answer
};

// Says what it is doing, a line at a time; false stops the fetch.
using FleetFetchProgress = std::function<bool(const std::string& line)>;

Expected<FleetFetchReport, std::string> fetchFromFleet(const FleetFetchRequest& request,
                                                       const FleetFetchProgress& progress = {});

}  // namespace wircam::recorder
