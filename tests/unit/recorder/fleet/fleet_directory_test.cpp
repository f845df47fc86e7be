// The fleet as a recorder sees it from the broker's messages (announcements,
// availability, statuses), and the announcement's own form and addresses.
#include "fleet/fleet_directory.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>

#include "fleet/recorder_id.h"

namespace {

using namespace wircam::recorder;
using Json = nlohmann::json;

Announcement recorderOf(const std::string& id, const std::string& prefix, const std::string& camera,
                        int64_t seen) {
  return {.id = id,
          .host = "node-" + id,
          .version = "1.0",
          .mqttPrefix = prefix,
          .http = "http://10.0.0.1:8080/",
          .cameras = {{camera, VehicleIdentity{"car-7", "S7"}, "/rover/cam0"}},
          .seenUnixMs = seen};
}

TEST(FleetAnnouncement, SaysWhatItParsesBack) {
  auto sent = recorderOf("a1", "lab/a", "rover-cam0", 1'700'000'000'000);
  auto back = announcementOf(toJson(sent).dump());
  ASSERT_TRUE(back);
  EXPECT_EQ(back->id, "a1");
  EXPECT_EQ(back->mqttPrefix, "lab/a");
  EXPECT_EQ(back->http, "http://10.0.0.1:8080/");
  ASSERT_EQ(back->cameras.size(), 1u);
  EXPECT_EQ(back->cameras[0].vehicle, (VehicleIdentity{"car-7", "S7"}));
  EXPECT_EQ(back->seenUnixMs, 1'700'000'000'000);
  EXPECT_EQ(announcementTopic("a1"), "wircam-fleet/recorders/a1");
}

TEST(FleetAnnouncement, RefusesWhatIsNotOne) {
  EXPECT_FALSE(announcementOf("not json"));
  EXPECT_FALSE(announcementOf("[1,2]"));
  EXPECT_FALSE(announcementOf(R"({"id":"a1"})"));  // no prefix: its topics unknown
  auto odd = announcementOf(R"({"id":"a1","mqtt_prefix":"p","cameras":[7,{"name":3},{"name":"c"}],
                                "urls":"no","seen_unix_ms":"soon"})");
  ASSERT_TRUE(odd);
  ASSERT_EQ(odd->cameras.size(), 1u);  // the one camera that is one
  EXPECT_FALSE(odd->cameras[0].vehicle);
  EXPECT_EQ(odd->seenUnixMs, 0);
}

TEST(FleetAnnouncement, AddressesOthersCanReach) {
  // A wildcard listening address is this machine's name; --fleet-url wins,
  // and its host stands for the other servers'.
  EXPECT_EQ(fleetHttpUrl("http://0.0.0.0:8080/", "", "node-a"), "http://node-a:8080/");
  EXPECT_EQ(fleetHttpUrl("http://127.0.0.1:8080/", "", "node-a"), "http://127.0.0.1:8080/");
  EXPECT_EQ(fleetHttpUrl("http://0.0.0.0:8080/", "https://cars.example/rec-a", "node-a"),
            "https://cars.example/rec-a/");
  EXPECT_EQ(fleetServiceUrl("rtsp://0.0.0.0:8554", "https://cars.example:9443/", "node-a"),
            "rtsp://cars.example:8554");
  EXPECT_EQ(fleetServiceUrl("ws://[::]:8765/", "", "node-a"), "ws://node-a:8765/");
  EXPECT_EQ(fleetServiceUrl("", "", "node-a"), "");
}

TEST(FleetDirectory, ARecorderIsOnlineFromItsAvailabilityWithItsCamerasStates) {
  FleetDirectory fleet;
  auto said = toJson(recorderOf("a1", "lab/a", "rover-cam0", 1000)).dump();
  // New: its prefix is to be followed, once.
  EXPECT_EQ(fleet.announced("wircam-fleet/recorders/a1", said, 5000), "lab/a");
  EXPECT_EQ(fleet.announced("wircam-fleet/recorders/a1", said, 6000), std::nullopt);
  auto view = fleet.view()["recorders"];
  ASSERT_EQ(view.size(), 1u);
  EXPECT_EQ(view[0]["online"], false);  // until it says online
  EXPECT_EQ(view[0]["cameras"][0]["state"], "unknown");

  EXPECT_TRUE(fleet.heard("lab/a/available", "online", 7000));
  EXPECT_TRUE(fleet.heard("lab/a/rover-cam0/status", R"({"state":"live","fps":15})", 8000));
  EXPECT_FALSE(fleet.heard("lab/a/rover-cam0/follow/set", "ON", 8000));  // a command: not ours
  EXPECT_FALSE(fleet.heard("lab/b/available", "online", 8000));          // nobody announced
  view = fleet.view()["recorders"];
  EXPECT_EQ(view[0]["online"], true);
  EXPECT_EQ(view[0]["cameras"][0]["state"], "live");
  EXPECT_EQ(view[0]["cameras"][0]["vehicle"]["serial"], "S7");
  EXPECT_EQ(view[0]["last_seen_utc"], "1970-01-01T00:00:08.000Z");

  // Its last will: offline, last seen when it went; what it said stays.
  EXPECT_TRUE(fleet.heard("lab/a/available", "offline", 9000));
  EXPECT_TRUE(fleet.heard("lab/a/rover-cam0/status", R"({"state":"live"})", 20000));
  view = fleet.view()["recorders"];
  EXPECT_EQ(view[0]["online"], false);
  EXPECT_EQ(view[0]["last_seen_utc"], "1970-01-01T00:00:09.000Z");
  EXPECT_EQ(view[0]["cameras"][0]["state"], "unknown");
  EXPECT_EQ(view[0]["cameras"][0]["status"]["state"], "live");
}

// A fleet too large to show whole is read a recorder at a time: the
// recorders with their counts, then one recorder's cameras.
TEST(FleetDirectory, IsViewedARecorderAtATimeOrWithCountsAlone) {
  FleetDirectory fleet;
  fleet.announced("wircam-fleet/recorders/a1", toJson(recorderOf("a1", "lab/a", "cam-a", 1)).dump(),
                  1000);
  fleet.announced("wircam-fleet/recorders/b2", toJson(recorderOf("b2", "lab/b", "cam-b", 1)).dump(),
                  1000);
  fleet.heard("lab/a/available", "online", 2000);
  fleet.heard("lab/a/cam-a/status", R"({"state":"live"})", 2000);
  auto counts = fleet.view({.cameras = false})["recorders"];
  ASSERT_EQ(counts.size(), 2u);
  for (const auto& r : counts) {
    EXPECT_FALSE(r.contains("cameras")) << r.dump();
    EXPECT_EQ(r["camera_count"], 1);
  }
  EXPECT_EQ(counts[0]["cameras_live"], 1);  // node-a1 first, by host
  EXPECT_EQ(counts[1]["cameras_live"], 0);
  auto one = fleet.view({.recorder = "b2"})["recorders"];
  ASSERT_EQ(one.size(), 1u);
  EXPECT_EQ(one[0]["id"], "b2");
  EXPECT_EQ(one[0]["cameras"][0]["name"], "cam-b");
  EXPECT_TRUE(fleet.view({.recorder = "nope"})["recorders"].empty());
}

// "Where is car 7?" among thousands of cameras: the ones whose name,
// vehicle or serial holds the text (case aside), or all a recorder's when
// its host or id does; recorders without one left out.
TEST(FleetDirectory, IsSearchedByCameraVehicleSerialOrRecorder) {
  FleetDirectory fleet;
  auto a = recorderOf("a1", "lab/a", "garage-cam0", 1);
  a.cameras.push_back({"garage-cam1", VehicleIdentity{"rover-2", "R2D2"}, ""});
  fleet.announced("wircam-fleet/recorders/a1", toJson(a).dump(), 1000);
  fleet.announced("wircam-fleet/recorders/b2",
                  toJson(recorderOf("b2", "lab/b", "yard-cam0", 1)).dump(), 1000);
  auto bySerial = fleet.view({.match = "r2d"})["recorders"];
  ASSERT_EQ(bySerial.size(), 1u);
  ASSERT_EQ(bySerial[0]["cameras"].size(), 1u);
  EXPECT_EQ(bySerial[0]["cameras"][0]["name"], "garage-cam1");
  EXPECT_EQ(bySerial[0]["camera_count"], 2);  // the recorder's own count, whole
  auto byVehicle = fleet.view({.match = "CAR-7"})["recorders"];
  ASSERT_EQ(byVehicle.size(), 2u);  // car-7 is seen by a camera of each
  EXPECT_EQ(byVehicle[0]["cameras"].size(), 1u);
  auto byRecorder = fleet.view({.match = "node-b2"})["recorders"];
  ASSERT_EQ(byRecorder.size(), 1u);
  EXPECT_EQ(byRecorder[0]["cameras"][0]["name"], "yard-cam0");
  EXPECT_TRUE(fleet.view({.match = "nothing like it"})["recorders"].empty());
}

TEST(FleetDirectory, ARetainedAnnouncementOfADeadRecorderSaysWhenItWasSeen) {
  FleetDirectory fleet;
  fleet.announced("wircam-fleet/recorders/a1",
                  toJson(recorderOf("a1", "lab/a", "rover-cam0", 42'000)).dump(), 99'000);
  fleet.heard("lab/a/available", "offline", 99'500);
  auto recorder = fleet.view()["recorders"][0];
  EXPECT_EQ(recorder["online"], false);
  EXPECT_EQ(recorder["last_seen_utc"], "1970-01-01T00:00:42.000Z");
}

TEST(FleetDirectory, TopicsGoToTheRecorderWithTheLongestPrefixAndAnEmptyAnnouncementForgets) {
  FleetDirectory fleet;
  fleet.announced("wircam-fleet/recorders/a", toJson(recorderOf("a", "lab", "x-cam0", 1)).dump(),
                  1);
  fleet.announced("wircam-fleet/recorders/b", toJson(recorderOf("b", "lab/b", "y-cam0", 1)).dump(),
                  1);
  fleet.heard("lab/b/available", "online", 2);
  fleet.heard("lab/available", "offline", 2);
  auto view = fleet.view()["recorders"];
  ASSERT_EQ(view.size(), 2u);
  for (const auto& r : view) EXPECT_EQ(r["online"], r["id"] == "b") << r.dump();
  EXPECT_EQ(fleet.prefixes().size(), 2u);
  // One announced under another's id, or not an announcement, is ignored.
  fleet.announced("wircam-fleet/recorders/c", toJson(recorderOf("a", "x", "z", 1)).dump(), 3);
  fleet.announced("wircam-fleet/recorders/d", "garbage", 3);
  EXPECT_EQ(fleet.view()["recorders"].size(), 2u);
  fleet.announced("wircam-fleet/recorders/a", "", 4);  // cleared by hand: retired
  EXPECT_EQ(fleet.view()["recorders"].size(), 1u);
}

TEST(FleetDirectory, ARecorderBackWithANewIdOnItsPrefixSupersedesItsOldSelf) {
  // Its folder replaced (a new id), its prefix kept: the old announcement
  // stays retained, the prefix's availability and statuses are the new one's.
  FleetDirectory fleet;
  fleet.announced("wircam-fleet/recorders/old",
                  toJson(recorderOf("old", "lab/yard", "nine-cam0", 1000)).dump(), 1000);
  fleet.heard("lab/yard/available", "online", 1500);
  EXPECT_EQ(fleet.announced("wircam-fleet/recorders/new",
                            toJson(recorderOf("new", "lab/yard", "nine-cam0", 9000)).dump(), 9000),
            std::nullopt);  // its prefix is followed already
  fleet.heard("lab/yard/available", "online", 9001);
  fleet.heard("lab/yard/nine-cam0/status", R"({"state":"live"})", 9002);
  std::map<std::string, Json> byId;
  auto view = fleet.view();
  for (const auto& r : view["recorders"]) byId[r["id"].get<std::string>()] = r;
  EXPECT_EQ(byId["new"]["online"], true);
  EXPECT_EQ(byId["new"]["cameras"][0]["state"], "live");
  EXPECT_EQ(byId["old"]["online"], false);
  EXPECT_EQ(byId["old"]["cameras"][0]["state"], "unknown");
  EXPECT_EQ(byId["old"]["last_seen_utc"], "1970-01-01T00:00:01.500Z");
}

TEST(RecorderId, IsMadeOnceAndKeptBesideTheRecordings) {
  auto folder =
      std::filesystem::temp_directory_path() / ("recorder-id-" + std::to_string(getpid()));
  std::filesystem::create_directories(folder);
  auto first = recorderId(folder);
  ASSERT_TRUE(first) << first.error();
  EXPECT_EQ(first->size(), 36u);  // a UUID
  EXPECT_EQ(*recorderId(folder), *first);
  std::ofstream(folder / kRecorderIdFile) << "a/b#\n";  // a topic level it cannot be
  auto refused = recorderId(folder);
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().find(kRecorderIdFile), std::string::npos);
  std::filesystem::remove_all(folder);
}

}  // namespace
