// A fleet as users set one up: three wirc-recorder processes on loopback,
// one real mosquitto, four simulated vehicles each with its own name and
// serial. One vehicle moves from the first recorder to the second by
// reloads mid-drive. The third recorder (--fleet) sees every recorder and
// camera with its vehicle, its one history across the two that recorded
// it, and a recorder killed with SIGKILL as offline, named in the history
// as not answering while the others answer on. Its page, in Chromium, shows
// every camera of the fleet with a live picture fetched from the recorder
// that holds it, and the killed recorder as offline. A command for the
// moved vehicle, by its serial, reaches the recorder that holds it now.
#include <gtest/gtest.h>
#include <signal.h>

#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>

#include "devices/wirc/device.h"
#include "devtools_page.h"
#include "headless_chromium.h"
#include "http_fetch.h"
#include "jpeg_sequence_scene.h"
#include "mqtt_broker.h"
#include "recorder_process.h"
#include "scene_frames.h"
#include "scratch_folder.h"
#include "shell_command.h"
#include "signed_in_page.h"
#include "wait_for.h"

namespace {

namespace fs = std::filesystem;
using namespace wircam;
using namespace wircam::testing;
using namespace std::chrono_literals;
using Json = nlohmann::json;

const Headers kAuthorized = {{"Authorization", std::string("Bearer ") + kToken}};

std::unique_ptr<wirc::Device> startVehicle(const std::string& name, const std::string& serial) {
  auto device = wirc::Device::start(
      {.port = 0, .name = name, .serial = serial, .fps = 15, .fragmentSize = 8000},
      std::make_shared<sim::JpegSequenceScene>(sceneFrames()));
  return device ? std::move(*device) : nullptr;
}

Json getJson(const std::string& url) {
  auto response = fetch(url, "GET", kAuthorized);
  return response.status == 200 ? Json::parse(response.body, nullptr, false) : Json();
}

// A recorder of the fleet: its devices in a config file ([device NAME]
// groups, rewritten for a reload), its servers on the command line.
class Member {
 public:
  Member(const fs::path& folder, const std::string& name, const MosquittoBroker& broker,
         const std::map<std::string, uint16_t>& devices, bool fleet = false,
         std::string settings = "")
      : config_(folder / (name + ".ini")), out_(folder / name), settings_(std::move(settings)) {
    write(devices);
    std::vector<std::string> args = {"--config",      config_.string(), "--http",   "127.0.0.1:0",
                                     "--http-token",  kToken,           "--mqtt",   broker.url(),
                                     "--mqtt-prefix", "fleet/" + name,  "--webrtc", "off"};
    if (fleet) args.push_back("--fleet");
    process_ = std::make_unique<RecorderProcess>(0, args);
    if (auto url = process_->waitForLog("http://", 10s)) url_ = *url;
  }
  void write(const std::map<std::string, uint16_t>& devices) {
    std::ofstream file(config_);
    file << "[recorder]\nout=" << out_.string() << "\nsegment=2\n" << settings_;
    for (const auto& [name, port] : devices)
      file << "[device " << name << "]\nhost=127.0.0.1\nport=" << port << "\n";
  }
  // Rewrites the config and reloads (SIGHUP), as an operator would.
  void reload(const std::map<std::string, uint16_t>& devices) {
    write(devices);
    process_->signal(SIGHUP);
  }
  const std::string& url() const { return url_; }
  RecorderProcess& process() { return *process_; }
  std::string id() const {
    std::ifstream in(out_ / ".wircam-recorder-id");
    std::string id;
    std::getline(in, id);
    return id;
  }

 private:
  fs::path config_, out_;
  std::string settings_;  // more of [recorder]
  std::unique_ptr<RecorderProcess> process_;
  std::string url_;
};

// The recorders of GET /api/fleet by id.
std::map<std::string, Json> recordersOf(const Json& fleet) {
  std::map<std::string, Json> byId;
  if (fleet.is_object())
    for (const auto& r : fleet.value("recorders", Json::array())) byId[r.value("id", "")] = r;
  return byId;
}

// Every camera of the fleet live, with the vehicle its device named.
bool allLiveWithVehicles(const Json& fleet, size_t recorders, size_t cameras) {
  auto byId = recordersOf(fleet);
  size_t live = 0;
  for (const auto& [id, r] : byId) {
    if (!r["online"].get<bool>()) return false;
    for (const auto& c : r["cameras"])
      live += c["state"] == "live" && c["vehicle"].is_object() ? 1 : 0;
  }
  return byId.size() == recorders && live == cameras;
}

// The spans the merged history leaves without a recording, in seconds,
// between its first start and its last end.
double longestHole(const Json& recordings) {
  std::vector<std::pair<double, double>> spans;
  for (const auto& r : recordings) {
    GDateTime* start =
        g_date_time_new_from_iso8601(r["start_utc"].get<std::string>().c_str(), nullptr);
    double from = g_date_time_to_unix(start) + g_date_time_get_microsecond(start) / 1e6;
    g_date_time_unref(start);
    spans.emplace_back(from, from + r["duration_s"].get<double>());
  }
  std::sort(spans.begin(), spans.end());
  double hole = 0, reached = spans.empty() ? 0 : spans[0].second;
  for (const auto& [from, to] : spans) {
    hole = std::max(hole, from - reached);
    reached = std::max(reached, to);
  }
  return hole;
}

// Now moved by `deltaMs`, as ISO 8601 UTC with milliseconds.
std::string isoNow(int64_t deltaMs) {
  GDateTime* now = g_date_time_new_now_utc();
  GDateTime* then = g_date_time_add(now, deltaMs * 1000);
  gchar* text = g_date_time_format(then, "%Y-%m-%dT%H:%M:%S.%fZ");
  std::string iso(text);
  g_free(text);
  g_date_time_unref(then);
  g_date_time_unref(now);
  return iso.substr(0, 23) + "Z";  // %f gives microseconds
}

double unixOf(const std::string& iso) {
  GDateTime* time = g_date_time_new_from_iso8601(iso.c_str(), nullptr);
  double seconds = g_date_time_to_unix(time) + g_date_time_get_microsecond(time) / 1e6;
  g_date_time_unref(time);
  return seconds;
}

// The first place two lists of digests part, with a few either side.
std::string whereTheyDiffer(const std::vector<std::string>& exported,
                            const std::vector<std::string>& expected) {
  size_t at = 0;
  while (at < exported.size() && at < expected.size() && exported[at] == expected[at]) ++at;
  std::string text = std::to_string(exported.size()) + " frames exported, " +
                     std::to_string(expected.size()) + " expected; first difference at " +
                     std::to_string(at) + ":\n";
  for (size_t i = at > 3 ? at - 3 : 0; i < at + 4; ++i)
    text += "  " + std::to_string(i) + ": " +
            (i < exported.size() ? exported[i].substr(0, 8) : std::string("-")) + "  " +
            (i < expected.size() ? expected[i].substr(0, 8) : std::string("-")) + "\n";
  return text;
}

// An ISO 8601 time to whole milliseconds since the epoch, in ns: the
// recordings' times are milliseconds, and a frame exactly at `--end` is in.
int64_t unixNsOf(const std::string& iso) { return std::llround(unixOf(iso) * 1e3) * 1000000; }

// The frames of a merged history up to `end`, each moment once: two
// recorders holding the vehicle at once got each of its frames, stamped
// each on its own arrival, milliseconds apart (a frame is 67 ms at 15 fps):
// another recorder's frame less than half a frame interval after the last
// moment is that moment (fleet.md). A recorder's own frames are each a
// moment, however close two came (a frame late, the next on time). Their
// digests in time order.
template <typename FileOf>
std::vector<std::string> momentsOf(const Json& recordings, const std::string& end, FileOf fileOf) {
  struct Frame {
    int64_t utcNs;
    std::string recorder;
    std::string digest;
    bool operator<(const Frame& other) const { return utcNs < other.utcNs; }
  };
  std::vector<Frame> frames;
  for (size_t n = 0; n < recordings.size(); ++n) {
    fs::path file = fileOf(recordings[n]);
    auto digests = frameDigests(file);
    auto pts = contentsOf(file).framePts;
    int64_t start = unixNsOf(recordings[n]["start_utc"]);
    for (size_t i = 0; i < std::min(digests.size(), pts.size()); ++i)
      frames.push_back(
          {start + static_cast<int64_t>(pts[i]), recordings[n]["recorder"], digests[i]});
  }
  std::stable_sort(frames.begin(), frames.end());
  std::vector<std::string> moments;
  std::optional<Frame> last;
  int64_t interval = 1000000000 / 15;  // the moments' last, as the export counts it
  int64_t upTo = unixNsOf(end);
  for (const auto& frame : frames) {
    if (frame.utcNs > upTo) continue;
    if (last && last->recorder != frame.recorder && frame.utcNs < last->utcNs + interval / 2)
      continue;
    if (last && frame.utcNs > last->utcNs && frame.utcNs - last->utcNs <= 1000000000)
      interval = frame.utcNs - last->utcNs;
    moments.push_back(frame.digest);
    last = frame;
  }
  return moments;
}

TEST(Fleet, ThreeRecordersOneBrokerAVehicleMovedMidDriveHasOneHistoryAndAKilledOneShowsOffline) {
  MosquittoBroker broker;
  ASSERT_TRUE(broker.running());
  std::map<std::string, std::unique_ptr<wirc::Device>> cars;
  for (int n = 1; n <= 4; ++n) {
    cars["car" + std::to_string(n)] =
        startVehicle("car-" + std::to_string(n), "S" + std::to_string(n));
    ASSERT_TRUE(cars["car" + std::to_string(n)]);
  }
  auto port = [&](const char* car) { return cars[car]->port(); };
  ScratchFolder scratch("wircam-fleet");  // before the recorders: it outlives them
  const fs::path& folder = scratch.path();

  Member first(folder, "first", broker, {{"car1", port("car1")}, {"car2", port("car2")}});
  // The second steers its vehicles after their tags.
  Member second(folder, "second", broker, {{"car3", port("car3")}}, false,
                "detect=tag36h11\nfollow=true\n");
  Member third(folder, "third", broker, {{"car4", port("car4")}}, true);
  for (Member* m : {&first, &second, &third}) ASSERT_FALSE(m->url().empty()) << m->process().log();

  // The fleet as the third recorder sees it: three recorders, four live
  // cameras, each with its vehicle.
  Json fleet;
  ASSERT_TRUE(waitFor(
      [&] {
        fleet = getJson(third.url() + "api/fleet");
        return allLiveWithVehicles(fleet, 3, 4);
      },
      20s))
      << fleet.dump(1) << "\n"
      << third.process().log();
  auto byId = recordersOf(fleet);
  ASSERT_TRUE(byId.contains(first.id()) && byId.contains(second.id()) && byId.contains(third.id()));
  EXPECT_EQ(byId[first.id()]["urls"]["http"], first.url());
  EXPECT_EQ(byId[first.id()]["mqtt_prefix"], "fleet/first");
  std::set<std::string> serials;
  for (const auto& [id, r] : byId)
    for (const auto& c : r["cameras"]) {
      serials.insert(c["vehicle"]["serial"].get<std::string>());
      // No recorder here serves RTSP: no path to play a camera from.
      EXPECT_EQ(r["urls"]["rtsp"], "");
      EXPECT_EQ(c["rtsp_path"], "") << c.dump();
    }
  EXPECT_EQ(serials, (std::set<std::string>{"S1", "S2", "S3", "S4"}));
  // The fleet on the third recorder's page: every camera with a picture
  // from its own recorder.
  std::unique_ptr<DevToolsPage> page;
  if (chromiumInstalled()) {
    page = DevToolsPage::launch(shotPath("fleet-page"), 1000, 1400);
    ASSERT_TRUE(page);
    ASSERT_TRUE(page->setCookie("wircam_token", kToken, third.url()));
    ASSERT_TRUE(page->navigate(third.url()));
    const std::string pictures =
        "[...document.querySelectorAll('.fleet-camera[data-state=live] img')]"
        ".filter(i => i.naturalWidth > 0).length";
    EXPECT_TRUE(page->waitUntil(pictures + " === 4", 20s)) << page->evaluate(pictures);
    EXPECT_EQ(
        page->evaluate("document.querySelectorAll('.fleet-recorder[data-online=true]').length"), 3);
    page->evaluate("document.getElementById('fleet').scrollIntoView()");
    page->screenshot(shotPath("fleet-page.png"));
    // "Where is S3?": typed into the search, only its camera shows; cleared,
    // all four again.
    const std::string shown =
        "[...document.querySelectorAll('.fleet-recorder:not([hidden]) .fleet-camera')]"
        ".map(c => c.dataset.camera).join(',')";
    page->evaluate("document.getElementById('fleet-search').focus()");
    for (char c : std::string("s3")) page->call("Input.insertText", {{"text", std::string(1, c)}});
    EXPECT_TRUE(page->waitUntil(shown + " === 'car3-cam0'", 10s)) << page->evaluate(shown);
    EXPECT_EQ(page->evaluate("document.getElementById('fleet-found').textContent"),
              "1 camera found");
    page->evaluate(
        "const box = document.getElementById('fleet-search'); box.value = '';"
        "box.dispatchEvent(new Event('input'))");
    EXPECT_TRUE(page->waitUntil(shown + ".split(',').length === 4", 10s)) << page->evaluate(shown);
  }
  // A recorder without --fleet says so.
  EXPECT_EQ(fetch(first.url() + "api/fleet", "GET", kAuthorized).status, 404u);
  // Searched by the API as by the page.
  auto found = getJson(third.url() + "api/fleet?match=s3")["recorders"];
  ASSERT_EQ(found.size(), 1u) << found.dump();
  ASSERT_EQ(found[0]["cameras"].size(), 1u) << found.dump();
  EXPECT_EQ(found[0]["cameras"][0]["name"], "car3-cam0");
  EXPECT_EQ(fetch(third.url() + "api/fleet?match=", "GET", kAuthorized).status, 400u);

  // car2 drives from the first recorder to the second: the second takes it
  // on (a reload), then the first lets it go (another).
  auto recordedOf = [&](Member& m, const char* vehicle) {
    return getJson(m.url() + "api/recordings?vehicle=" + vehicle);
  };
  ASSERT_TRUE(waitFor([&] { return recordedOf(first, "S2").size() >= 2; }, 20s));
  second.reload({{"car3", port("car3")}, {"car2", port("car2")}});
  ASSERT_TRUE(waitFor([&] { return recordedOf(second, "car-2").size() >= 1; }, 20s))
      << second.process().log();
  first.reload({{"car1", port("car1")}});
  ASSERT_TRUE(first.process().waitForText("1 removed", 20s)) << first.process().log();
  // The camera that left the first recorder leaves no retained status there
  // (a late subscriber gets car1's, not car2's).
  EXPECT_TRUE(waitFor(
      [&] {
        MqttProbe late(broker.port(), "fleet/first/+/status");
        if (!late.waitFor(
                "fleet/first/car1-cam0/status", [](auto&) { return true; }, 5s))
          return false;
        return late.messages("fleet/first/car2-cam0/status").empty();
      },
      10s));
  ASSERT_TRUE(waitFor([&] { return recordedOf(second, "S2").size() >= 3; }, 20s));

  // A command for the vehicle reaches it where it is now: the second
  // recorder's camera, the other vehicle there untouched.
  auto followingOf = [&](Member& m, const std::string& camera) {
    for (const auto& c : getJson(m.url() + "api/cameras"))
      if (c["name"] == camera) return c.value("following", Json());
    return Json();
  };
  ASSERT_TRUE(waitFor([&] { return followingOf(second, "car2-cam0") == true; }, 10s));
  MqttProbe commander(broker.port(), "wircam-fleet/vehicles/#");
  commander.publish("wircam-fleet/vehicles/S2/follow/set", "OFF");
  EXPECT_TRUE(waitFor([&] { return followingOf(second, "car2-cam0") == false; }, 10s))
      << second.process().log();
  EXPECT_EQ(followingOf(second, "car3-cam0"), true);
  commander.publish("wircam-fleet/vehicles/S2/follow/set", "ON");
  EXPECT_TRUE(waitFor([&] { return followingOf(second, "car2-cam0") == true; }, 10s));

  // Its one history, merged by time from both recorders, without a hole.
  Json history;
  ASSERT_TRUE(waitFor(
      [&] {
        history = getJson(third.url() + "api/fleet/recordings?vehicle=S2");
        std::set<std::string> from;
        for (const auto& r : history.value("recordings", Json::array()))
          from.insert(r["recorder"].get<std::string>());
        return from == std::set<std::string>{first.id(), second.id()};
      },
      20s))
      << history.dump(1);
  const auto& recordings = history["recordings"];
  for (size_t i = 1; i < recordings.size(); ++i)
    EXPECT_LE(recordings[i - 1]["start_utc"], recordings[i]["start_utc"]);
  EXPECT_LT(longestHole(recordings), 1.0) << history.dump(1);
  for (const auto& r : recordings) {
    EXPECT_EQ(r["vehicle"]["serial"], "S2");
    // Each entry's URL is its own recorder's, and serves the file.
    std::string url = r["url"];
    std::string owner = r["recorder"] == first.id() ? first.url() : second.url();
    EXPECT_TRUE(url.starts_with(owner)) << url;
  }
  auto file = fetch(recordings[0]["url"].get<std::string>(), "GET",
                    {{"Authorization", std::string("Bearer ") + kToken}, {"Range", "bytes=0-3"}});
  EXPECT_EQ(file.status, 206u);
  EXPECT_EQ(file.body, std::string("\x1a\x45\xdf\xa3", 4));  // Matroska's EBML magic

  // Its whole drive exported from the fleet, as a stranger would from
  // fleet.md: every moment either recorder recorded, once, up to a time
  // whose segments are all finished (they last 2 s).
  std::string end = isoNow(-5000);
  fs::path exported = folder / "car2.mkv";
  auto ran = runCommand(std::string(WIRC_EXPORT) + " --fleet " + broker.url() +
                        " --vehicle S2 --http-token " + kToken + " --end " + end +
                        " --format mkv --out '" + exported.string() + "'");
  ASSERT_EQ(ran.exitCode, 0) << ran.output;
  EXPECT_NE(ran.output.find("from 2 recorders (3 announced, 3 answered)"), std::string::npos)
      << ran.output;
  history = getJson(third.url() + "api/fleet/recordings?vehicle=S2");
  auto moments = momentsOf(history["recordings"], end, [&](const Json& r) {
    return (r["recorder"] == first.id() ? folder / "first" : folder / "second") /
           r["file"].get<std::string>();
  });
  auto exportedDigests = frameDigests(exported);
  EXPECT_EQ(exportedDigests, moments) << whereTheyDiffer(exportedDigests, moments) << ran.output;
  EXPECT_EQ(ffmpegDecodeErrors(exported), "");

  // The second recorder killed: offline within MQTT's keepalive (the broker
  // sees the socket go at once; a cut network would take 1.5 keepalives),
  // named in the history as not answering; the first answers on.
  second.process().signal(SIGKILL);
  ASSERT_TRUE(waitFor(
      [&] {
        fleet = getJson(third.url() + "api/fleet");
        auto now = recordersOf(fleet);
        return now.contains(second.id()) && now[second.id()]["online"] == false;
      },
      20s))
      << fleet.dump(1);
  EXPECT_EQ(recordersOf(fleet)[first.id()]["online"], true);
  if (page) {
    EXPECT_TRUE(page->waitUntil("document.querySelector('.fleet-recorder[data-id=\"" + second.id() +
                                "\"]').dataset.online === 'false'"));
    page->screenshot(shotPath("fleet-page-offline.png"));
  }
  history = getJson(third.url() + "api/fleet/recordings?vehicle=S2");
  bool secondNamed = false;
  for (const auto& r : history["recorders"]) {
    if (r["id"] == second.id()) {
      secondNamed = true;
      EXPECT_EQ(r["answered"], false);
      EXPECT_TRUE(r["error"].get<std::string>().starts_with("offline since")) << r.dump();
    }
    if (r["id"] == first.id()) {
      EXPECT_EQ(r["answered"], true);
    }
  }
  EXPECT_TRUE(secondNamed) << history.dump(1);
  for (const auto& r : history["recordings"]) EXPECT_EQ(r["recorder"], first.id());
  EXPECT_FALSE(history["recordings"].empty());
  // A day that is not one is refused, as on one recorder.
  EXPECT_EQ(fetch(third.url() + "api/fleet/recordings?day=2026-02-30", "GET", kAuthorized).status,
            400u);
}

// From the fleet section of one recorder's page, a vehicle another
// recorder holds is driven by its serial: the command goes to this
// recorder, through the broker, to the one that steers it; follow goes off
// first, the arrow key drives it, and letting go stops it. The vehicle
// of this page's own recorder is left alone.
TEST(Fleet, ThePagesFleetSectionDrivesAVehicleAnotherRecorderHolds) {
  if (!chromiumInstalled()) GTEST_SKIP() << "chromium is not installed";
  MosquittoBroker broker;
  ASSERT_TRUE(broker.running());
  auto held = startVehicle("car-a", "SA");
  auto own = startVehicle("car-b", "SB");
  ASSERT_TRUE(held && own);
  ScratchFolder scratch("wircam-fleet-drive");  // before the recorders: it outlives them
  const fs::path& folder = scratch.path();
  Member holder(folder, "holder", broker, {{"cara", held->port()}}, false,
                "detect=tag36h11\nfollow=true\n");
  Member fleet(folder, "fleet", broker, {{"carb", own->port()}}, true);
  ASSERT_FALSE(holder.url().empty() || fleet.url().empty()) << holder.process().log();
  auto page = DevToolsPage::launch(shotPath("fleet-drive"), 1000, 1000);
  ASSERT_TRUE(page);
  ASSERT_TRUE(page->setCookie("wircam_token", kToken, fleet.url()));
  ASSERT_TRUE(page->navigate(fleet.url()));
  const std::string card = ".fleet-camera[data-camera=\"cara-cam0\"]";
  ASSERT_TRUE(page->waitUntil(
      "!!document.querySelector('" + card + " .fleet-controls:not([hidden])')", 20s))
      << fleet.process().log();
  ASSERT_TRUE(page->clickOn(card + " .fleet-drive"));
  ASSERT_TRUE(page->waitUntil("document.querySelector('" + card + "').dataset.driving === 'true'"))
      << page->evaluate("document.querySelector('" + card + " .fleet-message').textContent");
  constexpr int kThrottle = 1;  // channel 2
  // Follow off, nothing pressed: the driver's neutral.
  EXPECT_TRUE(
      waitFor([&] { return held->outputs().pulses[kThrottle] == wirc::kPulseNeutral; }, 5s));
  page->key("keyDown", "ArrowUp");
  EXPECT_TRUE(waitFor([&] { return held->outputs().pulses[kThrottle] > wirc::kPulseNeutral; }, 5s))
      << holder.process().log();
  page->key("keyUp", "ArrowUp");
  EXPECT_TRUE(
      waitFor([&] { return held->outputs().pulses[kThrottle] == wirc::kPulseNeutral; }, 5s));
  EXPECT_EQ(own->outputs().pulses[kThrottle], wirc::kPulseNeutral);
  // The holding recorder's status says its vehicle no longer follows.
  EXPECT_TRUE(page->waitUntil("document.querySelector('" + card +
                              " .fleet-follow').textContent === 'following: off'"));
  page->screenshot(shotPath("fleet-drive.png"));
}

}  // namespace
