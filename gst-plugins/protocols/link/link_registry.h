// The links of one protocol in this process, shared by vehicle: the first
// user opens the link, later users that name the same vehicle get the same
// one, under the one settings policy of every protocol (SettingClaims: a
// setting is never dropped in silence, and a conflict names both users).
#pragma once

#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <utility>

#include "common/expected.h"
#include "link/shared_settings.h"

namespace wircam::link {

class EventLoop;

template <typename Link>
class LinkRegistry {
 public:
  // `settings` is what the link is opened with, as the user would read it
  // (all of them count as given: an open link cannot change them);
  // `open()` returns Expected<std::shared_ptr<Link>, std::string>. The
  // registry must outlive the links it hands out (a function's static).
  // Links on different event loops are different links (a test may own
  // a loop).
  template <typename Open>
  Expected<std::shared_ptr<Link>, std::string> acquire(const EventLoop& loop,
                                                       const std::string& key,
                                                       const SettingValues& settings,
                                                       const std::string& user, Open open) {
    std::lock_guard lock(mutex_);
    auto& entry = entries_[{&loop, key}];
    std::shared_ptr<Link> link = entry.link.lock();
    if (!link) {
      Expected<std::shared_ptr<Link>, std::string> opened = open();
      if (!opened) return opened;
      link = *opened;
      entry = {link, settings, std::make_shared<SettingClaims>()};
    }
    if (auto claimed = entry.claims->claim(key, user, settings, entry.settings, false); !claimed)
      return unexpected(claimed.error());
    return userReference(link, [this, claims = entry.claims, user] {
      std::lock_guard released(mutex_);
      claims->release(user);
    });
  }

 private:
  struct Entry {
    std::weak_ptr<Link> link;
    SettingValues settings;
    std::shared_ptr<SettingClaims> claims;
  };
  std::mutex mutex_;
  std::map<std::pair<const EventLoop*, std::string>, Entry> entries_;
};

}  // namespace wircam::link
