// A vehicle link: one process's connection to one vehicle, whatever its
// protocol (WiRC, RCOIP, BTEMP). Channel pulses go in; link state, the
// control right and status telemetry come out as typed events. Every user
// in the process that names the same vehicle shares one link.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "common/mutex.h"

namespace wircam::link {

// Pulse width per channel in µs, channel 1 first. WiRC has twelve
// (ch9..ch12 digital); other protocols map the channels they have.
constexpr size_t kChannels = 12;
constexpr uint16_t kPulseMin = 800;
constexpr uint16_t kPulseMax = 2200;
constexpr uint16_t kPulseNeutral = 1500;
using Pulses = std::array<uint16_t, kChannels>;

constexpr Pulses neutralPulses() {
  Pulses pulses{};
  pulses.fill(kPulseNeutral);
  return pulses;
}

enum class LinkState {
  Connecting,  // looking for the vehicle or logging in
  Live,        // logged in: commands reach the vehicle
  Lost,        // was live; trying again
  Failed,      // gave up (reconnect off, or a setting the vehicle refuses)
};
const char* linkStateName(LinkState state);

// What the vehicle last reported about itself.
struct Telemetry {
  std::optional<double> batteryVolts;
  std::optional<double> analogVolts;
  std::optional<int> rssi;
  std::optional<uint32_t> inputs;   // digital inputs as bits, input 1 first
  std::optional<uint32_t> outputs;  // digital outputs set, as bits (BTEMP)
  std::map<int, uint8_t> pdmDuty;   // output pin (from 0) → PDM duty 0..255 (BTEMP)
  std::chrono::steady_clock::time_point received;
};

// Events, delivered on the event loop thread in the order they happened.
struct StateChanged {
  LinkState state;
  std::string reason;  // why, for Lost and Failed; who, for Live
};
struct ControlRightChanged {
  bool hasControl;
  std::string holder;  // the transmitter holding it now, when known
};
// The outcome of requestControl().
struct ControlRequestAnswered {
  bool granted;
  std::string reason;
};
struct TelemetryReceived {
  Telemetry telemetry;
};
// The vehicle refused a request (WiRC ERR): code and the spec's meaning.
struct DeviceRefused {
  std::string request;
  int code;
  std::string meaning;
};
// Malformed input from the vehicle, summed up at most once a second (a
// hostile or broken peer costs a counter, not a message per byte).
struct InputRejected {
  uint64_t count;      // since the last summary
  std::string detail;  // by kind, e.g. "12 bad CRC, 3 unknown commands"
};
using LinkEvent = std::variant<StateChanged, ControlRightChanged, ControlRequestAnswered,
                               TelemetryReceived, DeviceRefused, InputRejected>;
std::string describe(const LinkEvent& event);

struct LinkStatus {
  LinkState state = LinkState::Connecting;
  std::string reason;
  std::string vehicleAddress;
  bool hasControl = false;
  std::optional<Telemetry> telemetry;  // the last report, however old (see its `received`)
  uint64_t logins = 0;                 // 1 after the first login, +1 per reconnect
  uint64_t commandsSent = 0;
  uint64_t inputRejected = 0;  // malformed messages from the vehicle, all connections
};

// Listeners: added and removed from any thread. Once remove() returns, the
// listener is not running and never runs again, so it may be called from a
// listener or a GStreamer bus sync handler alike. Listeners run on the event
// loop thread (but a WiRC status report, while its transmitter steers, on
// the thread whose keepalive read it: a stream's that lends its turns, or
// a command's): they must not block, and must not drop the last reference
// to their link (as a GStreamer application must not set a pipeline to
// NULL from a streaming thread).
//
// The link's state and control right are sticky, as GStreamer's sticky
// events are for a pad linked late: a listener added after the link logged
// in first hears the last StateChanged and ControlRightChanged, from add()
// on the caller's thread, then every later event. None is missed or heard
// twice, however the login and add() interleave.
class LinkListeners {
 public:
  using Listener = std::function<void(const LinkEvent&)>;
  int add(Listener listener);
  void remove(int id);
  void emit(const LinkEvent& event);

 private:
  Mutex mutex_;  // not held while a listener runs
  std::map<int, std::shared_ptr<const Listener>> listeners_ WIRCAM_GUARDED_BY(mutex_);
  int next_ WIRCAM_GUARDED_BY(mutex_) = 1;
  std::optional<StateChanged> lastState_ WIRCAM_GUARDED_BY(mutex_);
  std::optional<ControlRightChanged> lastControlRight_ WIRCAM_GUARDED_BY(mutex_);
  std::recursive_mutex emitting_;  // held while listeners run (emit may nest)
};

class VehicleLink {
 public:
  virtual ~VehicleLink() = default;

  // The pulses to send while holding the control right. A value that
  // differs from the last one sent leaves at once, from the caller's
  // thread (within the rate limit); otherwise a keepalive repeats it.
  // Out-of-range values are clamped: nothing outside 800..2200 leaves.
  virtual void setCommand(const Pulses& pulses) = 0;
  // Asks for the control right; the answer comes as ControlRequestAnswered.
  virtual void requestControl() = 0;
  virtual LinkStatus status() const = 0;

  int addListener(LinkListeners::Listener listener) { return listeners_.add(std::move(listener)); }
  void removeListener(int id) { listeners_.remove(id); }

 protected:
  LinkListeners listeners_;
};

}  // namespace wircam::link
