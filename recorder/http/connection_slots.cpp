#include "http/connection_slots.h"

namespace wircam::recorder {

std::optional<ConnectionSlots::Id> ConnectionSlots::admit(const std::string& address,
                                                          Clock::time_point now) {
  if (connections_.size() >= limits_.maxOpen || openFrom(address) >= limits_.maxPerAddress) {
    ++refused_;
    return std::nullopt;
  }
  Id id = next_++;
  connections_[id] = {.address = address, .idleSince = now};
  ++perAddress_[address];
  return id;
}

void ConnectionSlots::requestStarted(Id id) {
  if (auto it = connections_.find(id); it != connections_.end()) it->second.busy = true;
}

void ConnectionSlots::requestEnded(Id id, Clock::time_point now) {
  auto it = connections_.find(id);
  if (it == connections_.end() || it->second.upgraded) return;
  it->second.busy = false;
  it->second.idleSince = now;
}

void ConnectionSlots::upgraded(Id id) {
  if (auto it = connections_.find(id); it != connections_.end()) {
    it->second.upgraded = true;
    it->second.busy = true;
  }
}

void ConnectionSlots::closed(Id id) {
  auto it = connections_.find(id);
  if (it == connections_.end()) return;
  auto from = perAddress_.find(it->second.address);
  if (from != perAddress_.end() && --from->second == 0) perAddress_.erase(from);
  connections_.erase(it);
}

std::vector<ConnectionSlots::Id> ConnectionSlots::expired(Clock::time_point now) {
  std::vector<Id> due;
  for (auto& [id, connection] : connections_) {
    if (connection.busy || connection.closing) continue;
    if (now - connection.idleSince < limits_.idleTimeout) continue;
    connection.closing = true;
    due.push_back(id);
  }
  return due;
}

size_t ConnectionSlots::openFrom(const std::string& address) const {
  auto it = perAddress_.find(address);
  return it == perAddress_.end() ? 0 : it->second;
}

}  // namespace wircam::recorder
