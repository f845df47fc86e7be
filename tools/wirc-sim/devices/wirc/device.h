// A WiRC device (the WRCD of the spec) on real sockets: discovery, login,
// configuration, several transmitters with the control right, PCD with the
// failsafe timeout, PSD, and camera streams. It runs on its own thread; the
// pictures come from a DeviceScene. wirc-sim wraps it, and tests start it
// in-process on ephemeral loopback ports.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "common/expected.h"
#include "common/socket.h"
#include "devices/wirc/stream_sender.h"
#include "wirc/messages.h"

namespace wircam::wirc {

using DeviceClock = std::chrono::steady_clock;

// The pulses the device puts out now, after PCD or failsafe.
struct ChannelOutputs {
  ChannelValues pulses = neutralChannels();  // 0 = constant level (no pulse)
  bool failsafe = true;                      // no controller has sent PCD yet
};

// What the device's cameras look at. Called on the device thread only.
class DeviceScene {
 public:
  virtual ~DeviceScene() = default;
  // Moves the world to `now` under the given outputs (once per frame tick).
  virtual void advance(DeviceClock::time_point now, const ChannelOutputs& outputs) = 0;
  // The current picture of `camera` as a JPEG file.
  virtual std::vector<uint8_t> renderJpeg(int camera) = 0;
  // A scene with a timing of its own (a replayed recording): how long until
  // the next frame after the one just shown. Nothing: the device's --fps.
  virtual std::optional<DeviceClock::duration> frameInterval() { return std::nullopt; }
  // The battery the scene knows (a recording's), instead of the device's
  // own drain model.
  virtual std::optional<uint16_t> batteryMillivolts() { return std::nullopt; }
  // A scene that is watched rather than lived (a replay) stands still until
  // a stream is started, so that its first frame is the first one seen.
  virtual bool waitsForViewer() const { return false; }
  // A valid PCD from the controller arrived at `at`.
  virtual void pcdReceived(DeviceClock::time_point /*at*/, const ChannelValues& /*values*/) {}
};

struct DeviceConfig {
  std::string bindAddress = "127.0.0.1";
  uint16_t port = kDefaultPort;  // TCP control and UDP discovery; 0 = pick a free one
  std::string name = "wirc-sim";
  std::string serial = "SIM0001";
  Version hardware{1, 0};
  Version software{1, 3};
  int cameras = 1;
  double fps = 15;
  size_t fragmentSize = 64512;  // the real device's (protocols/NOTES.md)
  std::chrono::milliseconds pcdTimeout{kPcdTimeoutMs};
  std::chrono::milliseconds psdPeriod{kPsdPeriodMs};
  std::chrono::milliseconds restartTime{1000};  // after FWUP
  uint16_t batteryMillivolts = 8400;
  uint16_t emptyBatteryMillivolts = 6000;
  Impairments impairments;
  // When set, the car obeys these outputs (another protocol's receiver, as
  // wirc-sim --control rcoip|btemp) instead of the PCD it receives.
  std::function<ChannelOutputs(DeviceClock::time_point)> carControl;
};

struct DeviceStats {
  uint64_t framesSent = 0;       // frames handed to streams (per receiver)
  uint64_t framesSentWhole = 0;  // of those, frames no impairment took a packet from
  uint64_t activeStreams = 0;
  uint64_t datagramsSent = 0;
  uint64_t pcdReceived = 0;  // valid PCD from the controller
  uint64_t pcdRejected = 0;  // not from the controller, malformed or out of range
  uint64_t failsafeEntries = 0;
  uint64_t psdSent = 0;
  uint64_t errSent = 0;
  uint64_t logins = 0;
  uint64_t restarts = 0;
  uint64_t restartsDone = 0;               // listening again after a restart
  std::chrono::milliseconds maxPcdGap{0};  // longest wait between two PCD
  // Longest time between two frame ticks: a machine too busy to let the
  // device send on time (its frames are then skipped, not sent late).
  std::chrono::milliseconds maxTickGap{0};
};

class Device {
 public:
  using Logger = std::function<void(const std::string&)>;

  // Binds every socket and starts the device thread; an error names the
  // address that could not be bound.
  static Expected<std::unique_ptr<Device>, std::string> start(DeviceConfig config,
                                                              std::shared_ptr<DeviceScene> scene,
                                                              Logger logger = {});
  ~Device();
  Device(const Device&) = delete;
  Device& operator=(const Device&) = delete;

  uint16_t port() const;         // control (TCP) and discovery (UDP)
  uint16_t controlPort() const;  // where PCD goes (UDP), as sent in WST
  DeviceStats stats() const;
  ChannelOutputs outputs() const;
  // When the most recent valid PCD arrived (up to the last 4096), oldest
  // first: for measuring control latency from outside.
  std::vector<DeviceClock::time_point> pcdArrivals() const;
  std::string name() const;

  // Stops the thread and closes every connection.
  void stop();

  class Impl;

 private:
  explicit Device(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace wircam::wirc
