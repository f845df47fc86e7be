// What wirc-recorder was asked to do, read from its command line.
#pragma once

#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "common/expected.h"
#include "live/server_address.h"
#include "marvelmind/marvelmind_messages.h"

namespace wircam::recorder {

// What steers a following vehicle when it is not the WiRC device itself:
// "rcoip://HOST:PORT" or "btemp://HOST:PORT" (":PORT" optional: 9048,
// 16980; "wirc://" names another WiRC device).
struct ControlTarget {
  std::string protocol;  // wirc, rcoip or btemp
  std::string host;
  uint16_t port = 0;  // 0: the protocol's default
  bool operator==(const ControlTarget&) const = default;
};
Expected<ControlTarget, std::string> parseControlTarget(const std::string& uri);

// A Marvelmind dashboard and the vehicle's beacons on it.
struct PositionSource {
  std::string host;
  uint16_t port = marvelmind::kDefaultDashboardPort;
  std::string beacons;  // "5" or "5,6"
  bool operator==(const PositionSource&) const = default;
};

struct DeviceTarget {
  std::string host;  // empty: discover
  uint16_t port = 1984;
  std::string label;                     // in file names: the host, or the config section's name
  std::vector<int> cameras;              // empty: the recorder-wide --camera list
  std::optional<bool> follow;            // unset: the recorder-wide --follow
  std::optional<ControlTarget> control;  // unset: steer the WiRC device itself
  // Unset: the recorder-wide --marvelmind/--beacon, if any.
  std::optional<std::string> marvelmind;  // HOST[:PORT] of the dashboard
  std::optional<std::string> beacons;
  std::optional<PositionSource> positions;  // resolved from the two above
  bool operator==(const DeviceTarget&) const = default;
};

// "[HOST]:PORT" as the web, RTSP servers listen.
std::optional<ServerAddress> parseServerAddress(const std::string& text);

// How the frames are stored: as the camera sent them, or re-encoded.
enum class Codec { kJpeg, kH264 };
enum class Container { kMatroska, kMp4 };

struct RecorderOptions {
  std::vector<DeviceTarget> devices;
  std::vector<int> cameras;  // default {0}
  std::string outDir = ".";
  double segmentSeconds = 60;
  uint64_t segmentBytes = 0;  // 0: segments end by time only
  Container container = Container::kMatroska;
  Codec codec = Codec::kJpeg;
  // The telemetry as a text track in each file too (always in the sidecar).
  // Without it a stream is one thread and no hand-off per frame.
  bool telemetryTrack = true;
  // How much of each camera's video may wait for a slow disk, in bytes;
  // past it frames are dropped (and counted). 0: written on the camera's
  // own thread.
  uint64_t recordQueueBytes = 8'000'000;
  unsigned h264Kbps = 2000;
  std::string detectFamily;  // empty: no detection
  bool follow = false;       // needs detectFamily
  // The follower's tuning, as wirccontrol properties: " steering-kp=1.25 ..."
  // (checked names and numbers), appended to its element.
  std::string followTuning;
  std::optional<double> duration;
  double statusSeconds = 1;
  double stallSeconds = 5;  // logged in without a frame this long: no-video, restarted
  uint64_t maxBytes = 0;    // retention: 0 = unlimited
  uint64_t minFree = 0;
  std::chrono::seconds maxAge{0};         // retention by age: 0 = none
  std::chrono::seconds keepEvents{0};     // segments with tags or commands kept this long
  std::optional<ServerAddress> http;      // unset: no web server
  std::optional<ServerAddress> rtsp;      // unset: no RTSP server
  std::optional<ServerAddress> foxglove;  // unset: no Foxglove WebSocket
  unsigned foxgloveMaxClients = 8;
  double httpIdleSeconds = 10;  // a connection silent this long is closed
  std::string httpToken;        // empty: this machine only, no authentication
  // HTTPS: the server's certificate and key (PEM files), both or neither.
  std::string httpCert, httpKey;
  // The WebRTC live view beside MJPEG, with --http; its ICE servers (none:
  // nothing outside is contacted) and each camera's VP8 rate.
  bool webrtc = true;
  std::string webrtcStun, webrtcTurn;
  unsigned webrtcKbps = 600;
  // What the login tells the device (CCFG, FCFG), as channel lists; only the
  // first transmitter's login configures it. Unset: wircsrc's defaults.
  std::optional<std::string> periods;
  std::optional<std::string> failsafe;
  // Fleets: MQTT (unset: none) and the closed-segment hook (empty: none).
  std::optional<std::string> mqtt;  // mqtt://[user:pass@]HOST[:PORT] or mqtts://
  std::string mqttCaFile;           // mqtts://: the broker's CA (PEM)
  // Home Assistant's discovery prefix (--mqtt-discovery), or none.
  std::optional<std::string> mqttDiscovery;
  double mqttSnapshotSeconds = 10;  // the camera entity's pictures
  std::string mqttPrefix = "wircam";
  bool fleet = false;    // --fleet: the fleet directory (needs --mqtt and --http)
  std::string fleetUrl;  // --fleet-url: the HTTP address announced, if not the listening one
  double mqttDetectionsRate = 0;             // per second and stream at most; 0 = every frame
  std::vector<std::string> onSegmentClosed;  // the command and its arguments
  double hookTimeoutSeconds = 600;
  double hookDrainSeconds = 15;  // what the queue gets at exit
  // Marvelmind positions of every device that names none of its own.
  std::optional<std::string> marvelmind;  // HOST[:PORT]
  std::optional<std::string> beacons;
  std::string configFile;  // --config's: what a reload reads again (empty: none)
  // Each option's values as given (command line and config file), by name:
  // what a reload compares to find the changes it cannot take.
  std::map<std::string, std::vector<std::string>> given;
  bool operator==(const RecorderOptions&) const = default;
};

// The file name extension of a container, with its dot.
const char* extensionOf(Container container);

// The options, or an error message naming the bad argument; --help text in
// `usage()`. `--config FILE` reads a GKeyFile where it stands: options
// given on the command line after it override its [recorder] group. Every
// option is declared once, in app/option_table.h.
Expected<RecorderOptions, std::string> parseOptions(int argc, char** argv);
std::string usage();

// What a reload (the config file read again) cannot take without a restart
// of the recorder: the first option whose values changed and is not
// reloadable, with the reason; nothing if the new options may be applied.
std::optional<std::string> reloadRefusal(const RecorderOptions& running,
                                         const RecorderOptions& reread);

}  // namespace wircam::recorder
