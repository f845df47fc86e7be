// GET /api/fleet/recordings?vehicle=&camera=&day=: the fleet's one history.
// Each online recorder of the fleet directory is asked for its matching
// recordings (GET /api/recordings with the same query and this recorder's
// token: a fleet shares one), kMaxAsking at once, each within kAnswerTime;
// the answers are merged by start time, each entry naming its recorder and
// carrying an absolute URL. A recorder that is offline is not asked, and one
// that does not answer in time is not waited on: both are named with why,
// in "recorders", beside those that answered. Main loop only.
#pragma once

#include <libsoup/soup.h>

#include <chrono>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace wircam::recorder {

class FleetRecordings {
 public:
  static constexpr size_t kMaxAsking = 8;
  static constexpr std::chrono::seconds kAnswerTime{5};

  // `fleet`: GET /api/fleet's view (null: not a fleet recorder).
  FleetRecordings(std::function<nlohmann::json()> fleet, std::string token);
  ~FleetRecordings();  // cancels what is still asked
  FleetRecordings(const FleetRecordings&) = delete;
  FleetRecordings& operator=(const FleetRecordings&) = delete;

  // Answers at once with 400/404 JSON, or once every recorder answered or
  // ran out of time.
  void serve(SoupServerMessage* message, GHashTable* query);

 private:
  struct Gathering;
  struct Question;
  void askNext(const std::shared_ptr<Gathering>& gathering);
  void answered(Question* question, SoupMessage* asked, GBytes* body, GError* error);
  void finish(Gathering* gathering);

  std::function<nlohmann::json()> fleet_;
  std::string token_;
  SoupSession* session_;
  std::vector<std::shared_ptr<Gathering>> gatherings_;
};

}  // namespace wircam::recorder
