#include "link/vehicle_link.h"

namespace wircam::link {

const char* linkStateName(LinkState state) {
  switch (state) {
    case LinkState::Connecting:
      return "connecting";
    case LinkState::Live:
      return "live";
    case LinkState::Lost:
      return "lost";
    case LinkState::Failed:
      return "failed";
  }
  return "unknown";
}

std::string describe(const LinkEvent& event) {
  struct Describer {
    std::string operator()(const StateChanged& e) const {
      std::string text = std::string("link ") + linkStateName(e.state);
      return e.reason.empty() ? text : text + ": " + e.reason;
    }
    std::string operator()(const ControlRightChanged& e) const {
      if (e.hasControl) return "control right granted";
      return e.holder.empty() ? "control right lost" : "control right now with '" + e.holder + "'";
    }
    std::string operator()(const ControlRequestAnswered& e) const {
      return e.granted ? "control right request granted"
                       : "control right request denied: " + e.reason;
    }
    std::string operator()(const TelemetryReceived&) const { return "status report"; }
    std::string operator()(const InputRejected& e) const {
      return std::to_string(e.count) + " malformed messages from the vehicle in the last second (" +
             e.detail + ")";
    }
    std::string operator()(const DeviceRefused& e) const {
      return "the vehicle refused " + e.request + ": error " + std::to_string(e.code) + " (" +
             e.meaning + ")";
    }
  };
  return std::visit(Describer{}, event);
}

int LinkListeners::add(Listener listener) {
  // No event is emitted while this runs, so the sticky ones heard here and
  // the ones emitted after it neither overlap nor leave a gap.
  std::lock_guard emitting(emitting_);
  auto shared = std::make_shared<const Listener>(std::move(listener));
  std::optional<StateChanged> state;
  std::optional<ControlRightChanged> controlRight;
  int id;
  {
    MutexLock lock(mutex_);
    id = next_++;
    listeners_[id] = shared;
    state = lastState_;
    controlRight = lastControlRight_;
  }
  if (state) (*shared)(*state);
  if (controlRight) (*shared)(*controlRight);
  return id;
}

void LinkListeners::remove(int id) {
  // Waits for a running emit (unless this thread is the one emitting).
  std::lock_guard emitting(emitting_);
  MutexLock lock(mutex_);
  listeners_.erase(id);
}

void LinkListeners::emit(const LinkEvent& event) {
  std::lock_guard emitting(emitting_);
  std::vector<std::shared_ptr<const Listener>> current;
  {
    MutexLock lock(mutex_);
    if (const auto* state = std::get_if<StateChanged>(&event)) lastState_ = *state;
    if (const auto* right = std::get_if<ControlRightChanged>(&event)) lastControlRight_ = *right;
    current.reserve(listeners_.size());
    for (const auto& [id, listener] : listeners_) current.push_back(listener);
  }
  for (const auto& listener : current) (*listener)(event);
}

}  // namespace wircam::link
