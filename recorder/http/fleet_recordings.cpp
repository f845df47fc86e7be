#include "http/fleet_recordings.h"

#include <algorithm>
#include <set>
#include <tuple>

#include "http/http_responses.h"
#include "record/recording_query.h"

namespace wircam::recorder {

namespace {

constexpr std::chrono::seconds kGatherTime{10};

}  // namespace

// One request's gathering: who is asked, what came back. Shared with its
// questions, whose answers may come after it ended (cancelled, or the
// server gone).
struct FleetRecordings::Gathering {
  FleetRecordings* owner;
  SoupServerMessage* message;                      // null once the client left
  std::string query;                               // "?vehicle=..."
  nlohmann::json toAsk = nlohmann::json::array();  // recorders, in order
  size_t next = 0, asking = 0;
  nlohmann::json recordings = nlohmann::json::array();
  nlohmann::json recorders = nlohmann::json::array();  // each with what it said
  GCancellable* cancellable = g_cancellable_new();
  guint deadline = 0;
  gulong clientLeft = 0;
  bool done = false;
  ~Gathering() { g_object_unref(cancellable); }
};

struct FleetRecordings::Question {
  std::shared_ptr<Gathering> gathering;
  nlohmann::json recorder;  // its entry of the fleet view
};

FleetRecordings::FleetRecordings(std::function<nlohmann::json()> fleet, std::string token)
    : fleet_(std::move(fleet)), token_(std::move(token)) {
  session_ = soup_session_new_with_options(
      "timeout", static_cast<guint>(kAnswerTime.count()), "idle-timeout", 30u, "max-conns",
      static_cast<int>(kMaxAsking * 2), "user-agent", "wirc-recorder-fleet", nullptr);
}

FleetRecordings::~FleetRecordings() {
  for (auto& gathering : gatherings_) {
    gathering->owner = nullptr;
    gathering->done = true;
    if (gathering->deadline) g_source_remove(gathering->deadline);
    if (gathering->message && gathering->clientLeft)
      g_signal_handler_disconnect(gathering->message, gathering->clientLeft);
    g_cancellable_cancel(gathering->cancellable);
  }
  soup_session_abort(session_);
  g_object_unref(session_);
}

void FleetRecordings::serve(SoupServerMessage* message, GHashTable* query) {
  if (!fleet_)
    return respondJsonError(message, SOUP_STATUS_NOT_FOUND,
                            "this recorder was not started with --fleet (and --mqtt)");
  auto asked = recordingQueryOf(queryValue(query, "camera"), queryValue(query, "vehicle"),
                                queryValue(query, "day"));
  if (!asked) return respondJsonError(message, SOUP_STATUS_BAD_REQUEST, asked.error());
  auto gathering = std::make_shared<Gathering>();
  gathering->owner = this;
  gathering->message = message;
  gathering->query = queryString(*asked);
  for (const auto& recorder : fleet_().value("recorders", nlohmann::json::array())) {
    std::string url = recorder["urls"].value("http", "");
    nlohmann::json said = {{"id", recorder.value("id", "")},
                           {"host", recorder.value("host", "")},
                           {"answered", false}};
    if (!recorder.value("online", false))
      said["error"] = "offline since " + recorder.value("last_seen_utc", std::string("?"));
    else if (url.empty())
      said["error"] = "serves no HTTP";
    if (said.contains("error"))
      gathering->recorders.push_back(std::move(said));
    else
      gathering->toAsk.push_back(recorder);
  }
  gathering->clientLeft =
      g_signal_connect(message, "finished", G_CALLBACK(+[](SoupServerMessage*, gpointer data) {
                         auto* g = static_cast<Gathering*>(data);
                         g->message = nullptr;
                         g_cancellable_cancel(g->cancellable);
                       }),
                       gathering.get());
  gathering->deadline = g_timeout_add_seconds(
      kGatherTime.count(),
      [](gpointer data) {
        auto* g = static_cast<Gathering*>(data);
        g->deadline = 0;
        g->owner->finish(g);
        return G_SOURCE_REMOVE;
      },
      gathering.get());
  // A status now, or the WebSocket handler (which upgrades only unanswered
  // requests) would answer it; the body comes with the last answer.
  soup_server_message_set_status(message, SOUP_STATUS_OK, nullptr);
  soup_server_message_pause(message);
  gatherings_.push_back(gathering);
  askNext(gathering);
}

void FleetRecordings::askNext(const std::shared_ptr<Gathering>& gathering) {
  while (!gathering->done && gathering->asking < kMaxAsking &&
         gathering->next < gathering->toAsk.size()) {
    auto& recorder = gathering->toAsk[gathering->next++];
    std::string url = recorder["urls"].value("http", "") + "api/recordings" + gathering->query;
    SoupMessage* asked = soup_message_new("GET", url.c_str());
    if (!asked) {
      gathering->recorders.push_back({{"id", recorder.value("id", "")},
                                      {"host", recorder.value("host", "")},
                                      {"answered", false},
                                      {"error", "its URL " + url + " is not one"}});
      continue;
    }
    if (!token_.empty())
      soup_message_headers_replace(soup_message_get_request_headers(asked), "Authorization",
                                   ("Bearer " + token_).c_str());
    auto* question = new Question{gathering, recorder};
    ++gathering->asking;
    soup_session_send_and_read_async(
        session_, asked, G_PRIORITY_DEFAULT, gathering->cancellable,
        [](GObject* session, GAsyncResult* result, gpointer data) {
          auto* pending = static_cast<Question*>(data);
          GError* error = nullptr;
          GBytes* body = soup_session_send_and_read_finish(SOUP_SESSION(session), result, &error);
          SoupMessage* message =
              soup_session_get_async_result_message(SOUP_SESSION(session), result);
          auto* owner = pending->gathering->owner;
          if (owner) owner->answered(pending, message, body, error);
          if (body) g_bytes_unref(body);
          g_clear_error(&error);
          if (message) g_object_unref(message);
          delete pending;
        },
        question);
  }
  if (gathering->asking == 0 && gathering->next >= gathering->toAsk.size()) finish(gathering.get());
}

void FleetRecordings::answered(Question* question, SoupMessage* asked, GBytes* body,
                               GError* error) {
  const auto& gathering = question->gathering;
  --gathering->asking;
  if (gathering->done) return;
  const auto& recorder = question->recorder;
  std::string base = recorder["urls"].value("http", "");
  nlohmann::json said = {
      {"id", recorder.value("id", "")}, {"host", recorder.value("host", "")}, {"answered", false}};
  guint status = asked ? soup_message_get_status(asked) : 0;
  nlohmann::json list;
  if (body) {
    gsize size = 0;
    auto* bytes = static_cast<const char*>(g_bytes_get_data(body, &size));
    list = nlohmann::json::parse(std::string_view(bytes, size), nullptr, false);
  }
  if (error)
    said["error"] = std::string("no answer: ") + error->message;
  else if (status != SOUP_STATUS_OK)
    said["error"] =
        "answered " + std::to_string(status) +
        (status == SOUP_STATUS_UNAUTHORIZED ? " (its --http-token is not this one's)" : "");
  else if (!list.is_array())
    said["error"] = "answered no list of recordings";
  if (said.contains("error")) {
    gathering->recorders.push_back(std::move(said));
  } else {
    for (auto& entry : list) {
      if (!entry.is_object()) continue;
      entry["recorder"] = said["id"];
      entry["recorder_host"] = said["host"];
      std::string path = entry.value("url", "");
      if (path.starts_with("/")) entry["url"] = base + path.substr(1);
      gathering->recordings.push_back(std::move(entry));
    }
    said["answered"] = true;
    said["recordings"] = list.size();
    gathering->recorders.push_back(std::move(said));
  }
  askNext(gathering);
}

void FleetRecordings::finish(Gathering* gathering) {
  if (gathering->done) return;
  gathering->done = true;
  if (gathering->deadline) g_source_remove(gathering->deadline);
  gathering->deadline = 0;
  g_cancellable_cancel(gathering->cancellable);
  // Who was still asked, or never reached, when time ran out.
  std::set<std::string> said;
  for (const auto& r : gathering->recorders) said.insert(r.value("id", ""));
  for (const auto& recorder : gathering->toAsk) {
    std::string id = recorder.value("id", "");
    if (!said.count(id))
      gathering->recorders.push_back(
          {{"id", id},
           {"host", recorder.value("host", "")},
           {"answered", false},
           {"error", "no answer within " + std::to_string(kGatherTime.count()) + " s"}});
  }
  // As /api/fleet lists them, whatever order they answered in.
  auto& recorders = gathering->recorders;
  std::stable_sort(recorders.begin(), recorders.end(), [](const auto& a, const auto& b) {
    return std::tie(a["host"].template get_ref<const std::string&>(),
                    a["id"].template get_ref<const std::string&>()) <
           std::tie(b["host"].template get_ref<const std::string&>(),
                    b["id"].template get_ref<const std::string&>());
  });
  // By start, each start read once (thousands of recordings from 100
  // recorders: not a parse per comparison).
  std::vector<std::pair<int64_t, nlohmann::json*>> byStart;
  for (auto& r : gathering->recordings)
    byStart.emplace_back(unixMsOfUtc(r.value("start_utc", "")).value_or(0), &r);
  std::stable_sort(byStart.begin(), byStart.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  nlohmann::json recordings = nlohmann::json::array();
  for (auto& [start, r] : byStart) recordings.push_back(std::move(*r));
  if (SoupServerMessage* message = gathering->message) {
    g_signal_handler_disconnect(message, gathering->clientLeft);
    gathering->message = nullptr;
    respond(message, SOUP_STATUS_OK, "application/json",
            nlohmann::json{{"recordings", std::move(recordings)}, {"recorders", recorders}}.dump());
    soup_server_message_unpause(message);
  }
  // Forgotten from the main loop's next turn: its questions' answers still
  // hold it (shared) until they come back cancelled.
  std::erase_if(gatherings_, [&](auto& g) { return g.get() == gathering; });
}

}  // namespace wircam::recorder
