#include "link/shared_settings.h"

#include <optional>

namespace wircam::link {

namespace {

std::string named(const std::string& user) { return user.empty() ? "a user" : user; }

}  // namespace

Expected<std::vector<std::string>, std::string> SettingClaims::claim(const std::string& key,
                                                                     const std::string& user,
                                                                     const SettingValues& given,
                                                                     const SettingValues& current,
                                                                     bool canChange) {
  std::vector<std::string> changes;
  for (const auto& [name, wanted] : given) {
    auto found = current.find(name);
    if (found == current.end() || found->second == wanted) continue;
    std::optional<std::string> other;
    for (const auto& claimant : claimants_[name])
      if (claimant != user) other = claimant;
    std::string asked = name + "=" + wanted + " of " + named(user);
    if (other)
      return unexpected(asked + " conflicts with " + name + "=" + found->second + " of " +
                        named(*other) + ", which shares the link to " + key +
                        ": give both the same value, or set it on one only");
    if (!canChange)
      return unexpected(asked + " differs from the " + name + "=" + found->second +
                        " the link to " + key +
                        " is open with, which cannot change while it is in use: give every "
                        "user of one vehicle the same value");
    changes.push_back(name);
  }
  for (const auto& [name, wanted] : given) claimants_[name].insert(user);
  return changes;
}

void SettingClaims::release(const std::string& user) {
  for (auto& [name, users] : claimants_) users.erase(user);
}

}  // namespace wircam::link
