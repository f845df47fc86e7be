// The links of one protocol in this process, shared by vehicle: the first
// user opens the link, later users that name the same vehicle get the same
// one, under the one settings policy of every protocol (SettingClaims: a
// setting is never dropped in silence, and a conflict names both users).
// WiRC, RCOIP and BTEMP all share their links through it.
#pragma once

#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

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
    return share(
        loop, key, user, settings, open,
        [&](Entry& entry, Link&) {
          return entry.claims->claim(key, user, settings, entry.openedWith, false);
        },
        [](Link&, const std::vector<std::string>&) {});
  }

  // The same for a link whose settings can change while it is open (WiRC
  // logs in again): `given` are the settings the user gave, `current(link)`
  // reads the link's own, and `adopt(link, names)` takes over those of
  // `given` named (ones nobody else gave). It runs for every user, with no
  // names when nothing changes, under the registry's lock: it must not
  // block.
  template <typename Open, typename Current, typename Adopt>
  Expected<std::shared_ptr<Link>, std::string> acquireChangeable(const EventLoop& loop,
                                                                 const std::string& key,
                                                                 const SettingValues& given,
                                                                 const std::string& user, Open open,
                                                                 Current current, Adopt adopt) {
    return share(
        loop, key, user, {}, open,
        [&](Entry& entry, Link& link) {
          return entry.claims->claim(key, user, given, current(link), true);
        },
        adopt);
  }

 private:
  struct Entry {
    std::weak_ptr<Link> link;
    SettingValues openedWith;  // acquire's: the settings an open link keeps
    std::shared_ptr<SettingClaims> claims;
  };

  // The link for (loop, key), opened if none is; `user` claims its settings,
  // and the changes claimed are adopted.
  template <typename Open, typename Claim, typename Adopt>
  Expected<std::shared_ptr<Link>, std::string> share(const EventLoop& loop, const std::string& key,
                                                     const std::string& user,
                                                     const SettingValues& openedWith, Open open,
                                                     Claim claim, Adopt adopt) {
    std::lock_guard lock(mutex_);
    auto& entry = entries_[{&loop, key}];
    std::shared_ptr<Link> link = entry.link.lock();
    if (!link) {
      Expected<std::shared_ptr<Link>, std::string> made = open();
      if (!made) return made;
      link = *made;
      entry = {link, openedWith, std::make_shared<SettingClaims>()};
    }
    auto changes = claim(entry, *link);
    if (!changes) return unexpected(changes.error());
    adopt(*link, *changes);
    return userReference(link, [this, claims = entry.claims, user] {
      std::lock_guard released(mutex_);
      claims->release(user);
    });
  }

  std::mutex mutex_;
  std::map<std::pair<const EventLoop*, std::string>, Entry> entries_;
};

}  // namespace wircam::link
