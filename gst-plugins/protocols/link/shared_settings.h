// How the users of one shared vehicle link agree on its settings, one policy
// for WiRC, RCOIP and BTEMP. Each setting a user gives is compared with the
// link's: a different value that another user of the link gave is a conflict
// naming both users, the setting and both values; a different value nobody
// gave is taken over where the link can change it (WiRC logs in again with
// it) and a conflict where it cannot. A user's claims end when it lets go.
#pragma once

#include <map>
#include <memory>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "common/expected.h"

namespace wircam::link {

// Setting name → value as a user reads it ("lost-timeout" → "500 ms").
using SettingValues = std::map<std::string, std::string>;

class SettingClaims {
 public:
  // `user` gives `given` for the link to `key`, which now has `current`.
  // Returns the names whose value changes (taken over when `canChange`),
  // or the conflict; on success `user` holds its claims.
  Expected<std::vector<std::string>, std::string> claim(const std::string& key,
                                                        const std::string& user,
                                                        const SettingValues& given,
                                                        const SettingValues& current,
                                                        bool canChange);
  void release(const std::string& user);

 private:
  std::map<std::string, std::set<std::string>> claimants_;  // setting → users who gave it
};

// A user's own reference to a shared link: when the user lets go,
// `release` runs (its claims end), then the link goes if it was the last.
template <typename Link, typename Release>
std::shared_ptr<Link> userReference(std::shared_ptr<Link> link, Release release) {
  auto* strong = new std::shared_ptr<Link>(std::move(link));
  return std::shared_ptr<Link>(strong->get(), [strong, release = std::move(release)](Link*) {
    release();
    delete strong;
  });
}

}  // namespace wircam::link
