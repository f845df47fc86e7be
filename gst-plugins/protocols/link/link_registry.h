// The links of one protocol in this process, shared by vehicle: the first
// user opens the link, later users that name the same vehicle get the same
// one when they ask for the same settings, and an error naming both when not
// (a setting is never dropped in silence).
#pragma once

#include <map>
#include <memory>
#include <mutex>
#include <string>

#include "common/expected.h"

namespace wircam::link {

template <typename Link>
class LinkRegistry {
 public:
  // `settings` is what the link is opened with, as the user would read it;
  // `open()` returns Expected<std::shared_ptr<Link>, std::string>.
  template <typename Open>
  Expected<std::shared_ptr<Link>, std::string> acquire(const std::string& key,
                                                       const std::string& settings, Open open) {
    std::lock_guard lock(mutex_);
    auto& entry = entries_[key];
    if (auto link = entry.link.lock()) {
      if (entry.settings != settings)
        return unexpected("the link to " + key + " is open with " + entry.settings +
                          "; this user asks for " + settings +
                          ": give every user of one vehicle the same settings");
      return link;
    }
    Expected<std::shared_ptr<Link>, std::string> opened = open();
    if (opened) entry = {*opened, settings};
    return opened;
  }

 private:
  struct Entry {
    std::weak_ptr<Link> link;
    std::string settings;
  };
  std::mutex mutex_;
  std::map<std::string, Entry> entries_;
};

}  // namespace wircam::link
