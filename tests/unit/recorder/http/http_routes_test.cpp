// Which resource a request path names, and which recording names are served.
#include "http/http_routes.h"

#include <gtest/gtest.h>

namespace wircam::recorder {
namespace {

using Kind = Route::Kind;

TEST(HttpRoutes, NamesEveryResource) {
  EXPECT_EQ(routeOf("/").kind, Kind::Page);
  EXPECT_EQ(routeOf("/index.html").kind, Kind::Page);
  EXPECT_EQ(routeOf("/api/status").kind, Kind::Status);
  EXPECT_EQ(routeOf("/api/events").kind, Kind::Events);
  EXPECT_EQ(routeOf("/recordings").kind, Kind::RecordingList);
  EXPECT_EQ(routeOf("/recordings/").kind, Kind::RecordingList);
  auto live = routeOf("/live/rover-cam0.mjpg");
  EXPECT_EQ(live.kind, Kind::Live);
  EXPECT_EQ(live.name, "rover-cam0");
  auto file = routeOf("/recordings/rover-cam0-000.mkv");
  EXPECT_EQ(file.kind, Kind::Recording);
  EXPECT_EQ(file.name, "rover-cam0-000.mkv");
  auto whep = routeOf("/api/cameras/rover-cam0/whep");
  EXPECT_EQ(whep.kind, Kind::Whep);
  EXPECT_EQ(whep.name, "rover-cam0");
  auto session = routeOf("/api/cameras/rover-cam0/whep/5d2f0f2c-1d4b");
  EXPECT_EQ(session.kind, Kind::WhepSession);
  EXPECT_EQ(session.name, "rover-cam0");
  EXPECT_EQ(session.action, "5d2f0f2c-1d4b");
  EXPECT_EQ(routeOf("/api/cameras/rover-cam0/whep/").kind, Kind::ApiNotFound);
  EXPECT_EQ(routeOf("/api/cameras/rover-cam0/whep/a/b").kind, Kind::ApiNotFound);
  EXPECT_EQ(routeOf("/live/.mjpg").kind, Kind::NotFound);
  EXPECT_EQ(routeOf("/etc/passwd").kind, Kind::NotFound);
}

TEST(HttpRoutes, TheTokenComesAsBearerOrCookie) {
  std::string token = "0123456789abcdef";
  EXPECT_TRUE(carriesToken(nullptr, nullptr, ""));  // no token set: everyone
  EXPECT_FALSE(carriesToken(nullptr, nullptr, token));
  EXPECT_TRUE(carriesToken("Bearer 0123456789abcdef", nullptr, token));
  EXPECT_FALSE(carriesToken("Bearer 0123456789abcde", nullptr, token));
  EXPECT_FALSE(carriesToken("Bearer 0123456789abcdef0", nullptr, token));
  EXPECT_FALSE(carriesToken("Basic 0123456789abcdef", nullptr, token));
  // Basic: the token as the password, any user name ("u:0123456789abcdef").
  EXPECT_TRUE(carriesToken("Basic dTowMTIzNDU2Nzg5YWJjZGVm", nullptr, token));
  EXPECT_TRUE(carriesToken("Basic OjAxMjM0NTY3ODlhYmNkZWY=", nullptr, token));   // no user
  EXPECT_FALSE(carriesToken("Basic dTowMTIzNDU2Nzg5YWJjZGU=", nullptr, token));  // one short
  EXPECT_FALSE(carriesToken("Basic MDEyMzQ1Njc4OWFiY2RlZg==", nullptr, token));  // no colon
  EXPECT_FALSE(carriesToken("Basic !!!", nullptr, token));
  // The scheme's name in any case (RFC 9110 11.1); lowercase was refused.
  EXPECT_TRUE(carriesToken("bearer 0123456789abcdef", nullptr, token));
  EXPECT_TRUE(carriesToken("BASIC dTowMTIzNDU2Nzg5YWJjZGVm", nullptr, token));
  EXPECT_FALSE(carriesToken("bearer0123456789abcdef", nullptr, token));
  EXPECT_TRUE(carriesToken(nullptr, "a=1; wircam_token=0123456789abcdef; b=2", token));
  EXPECT_TRUE(carriesToken(nullptr, "wircam_token=0123456789abcdef", token));
  EXPECT_FALSE(carriesToken(nullptr, "xwircam_token=0123456789abcdef", token));
  EXPECT_FALSE(carriesToken(nullptr, "wircam_token=", token));
  EXPECT_EQ(routeOf("/login").kind, Kind::Login);
}

TEST(HttpRoutes, NamesTheCameraAndRecordingApi) {
  EXPECT_EQ(routeOf("/api/cameras").kind, Kind::Cameras);
  EXPECT_EQ(routeOf("/api/recordings").kind, Kind::RecordingIndex);
  EXPECT_EQ(routeOf("/api/export").kind, Kind::Export);
  EXPECT_EQ(routeOf("/api/export/x").kind, Kind::ApiNotFound);
  auto snapshot = routeOf("/api/cameras/rover-cam0/snapshot.jpg");
  EXPECT_EQ(snapshot.kind, Kind::Snapshot);
  EXPECT_EQ(snapshot.name, "rover-cam0");
  // Other /api/ paths are answered in JSON, not as the page's 404.
  for (const char* other : {"/api/cameras/snapshot.jpg", "/api/cameras/a/b/snapshot.jpg",
                            "/api/cameras/rover-cam0", "/api/nothing"})
    EXPECT_EQ(routeOf(other).kind, Kind::ApiNotFound) << other;
}

TEST(HttpRoutes, NamesTheControlDriveAndPlaybackResources) {
  for (const char* action : {"follow", "target", "request-control"}) {
    auto command = routeOf(std::string("/api/cameras/rover-cam0/") + action);
    EXPECT_EQ(command.kind, Kind::CameraCommand) << action;
    EXPECT_EQ(command.name, "rover-cam0");
    EXPECT_EQ(command.action, action);
  }
  auto drive = routeOf("/api/cameras/rover-cam0/drive");
  EXPECT_EQ(drive.kind, Kind::Drive);
  EXPECT_EQ(drive.name, "rover-cam0");
  auto play = routeOf("/play/rover-cam0-20261122T101500Z.mkv.mjpg");
  EXPECT_EQ(play.kind, Kind::Playback);
  EXPECT_EQ(play.name, "rover-cam0-20261122T101500Z.mkv");
  for (const char* other :
       {"/api/cameras//drive", "/api/cameras/a/steer", "/api/cameras/a/drive/x"})
    EXPECT_EQ(routeOf(other).kind, Kind::ApiNotFound) << other;
  EXPECT_EQ(routeOf("/play/.mjpg").kind, Kind::NotFound);
}

TEST(HttpRoutes, NamesAFleetVehiclesCommandsBySerial) {
  for (const char* action : {"follow", "target", "drive"}) {
    auto command = routeOf(std::string("/api/fleet/vehicles/W000123/") + action);
    EXPECT_EQ(command.kind, Kind::FleetVehicleCommand) << action;
    EXPECT_EQ(command.name, "W000123");
    EXPECT_EQ(command.action, action);
  }
  EXPECT_STREQ(allowedMethods(Kind::FleetVehicleCommand), "POST");
  for (const char* other :
       {"/api/fleet/vehicles/W000123", "/api/fleet/vehicles//drive",
        "/api/fleet/vehicles/W000123/request-control", "/api/fleet/vehicles/a/b/drive"})
    EXPECT_EQ(routeOf(other).kind, Kind::ApiNotFound) << other;
}

TEST(HttpRoutes, ServesOnlyPlainNamesOfRecordings) {
  EXPECT_TRUE(isRecordingName("rover-cam0-000.mkv"));
  EXPECT_TRUE(isRecordingName("rover-cam0-000.jsonl"));
  EXPECT_TRUE(isRecordingName("rover-cam0-000.mp4"));
  for (const char* refused :
       {"", "../secret.mkv", "a/b.mkv", ".hidden.mkv", "stderr.log", "passwd", "x.mkv.bak"})
    EXPECT_FALSE(isRecordingName(refused)) << refused;
  EXPECT_FALSE(isRecordingName(std::string_view("a\0b.mkv", 7)));
}

TEST(HttpRoutes, EachResourceSaysTheMethodsItServes) {
  auto allowed = [](const char* path) { return std::string(allowedMethods(routeOf(path).kind)); };
  EXPECT_EQ(allowed("/api/cameras"), "GET");
  EXPECT_EQ(allowed("/api/cameras/rover-cam0/follow"), "POST");
  EXPECT_EQ(allowed("/api/cameras/rover-cam0/whep/5d2f"), "DELETE");
  EXPECT_EQ(allowed("/api/recordings/a.mkv"), "DELETE");
  EXPECT_EQ(allowed("/recordings/a.mkv"), "GET, HEAD, DELETE");
  EXPECT_EQ(allowed("/api/status"), "GET, HEAD");
  EXPECT_EQ(allowed("/live/rover-cam0.mjpg"), "GET");
  // A path that names nothing is a 404 whatever the method.
  EXPECT_EQ(allowedMethods(routeOf("/api/nothing").kind), nullptr);
  EXPECT_EQ(allowedMethods(routeOf("/nothing").kind), nullptr);
}

TEST(HttpRoutes, AMethodIsAllowedOnlyAsAWholeWordOfTheList) {
  EXPECT_TRUE(methodAllowed("GET, HEAD, DELETE", "GET"));
  EXPECT_TRUE(methodAllowed("GET, HEAD, DELETE", "HEAD"));
  EXPECT_TRUE(methodAllowed("GET, HEAD, DELETE", "DELETE"));
  EXPECT_FALSE(methodAllowed("GET, HEAD, DELETE", "POST"));
  EXPECT_FALSE(methodAllowed("GET, HEAD", "GE"));
  EXPECT_FALSE(methodAllowed("GET, HEAD", "EAD"));
  EXPECT_FALSE(methodAllowed("GET", ""));
  EXPECT_FALSE(methodAllowed(nullptr, "GET"));
}

}  // namespace
}  // namespace wircam::recorder
