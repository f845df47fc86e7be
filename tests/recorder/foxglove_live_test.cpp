// wirc-recorder --foxglove: Foxglove's own WebSocket client
// (@foxglove/ws-protocol, foxglove_client/client.mjs) sees each camera's
// image, tags, telemetry, log and pose, decoded with Foxglove's schemas;
// drives the simulated car from /STREAM/drive with the web page's dead-man;
// and neither a slow client, nor one too many, nor junk costs the others.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <thread>

#include "devices/wirc/device.h"
#include "follow_scene.h"
#include "foxglove_client.h"
#include "http_fetch.h"
#include "marvelmind_dashboard.h"
#include "process_memory.h"
#include "recorder_process.h"
#include "shell_command.h"
#include "signed_in_page.h"
#include "simulated_device.h"
#include "wait_for.h"

namespace {

namespace fs = std::filesystem;
using namespace wircam;
using namespace wircam::testing;
using namespace std::chrono_literals;
using nlohmann::json;

std::string cameraOf(uint16_t port) { return "127.0.0.1-" + std::to_string(port) + "-cam0"; }

// The Foxglove server's ws:// address, from the recorder's log.
std::string foxgloveUrl(RecorderProcess& recorder) {
  auto url = recorder.waitForLog("ws://", 15s);
  EXPECT_TRUE(url) << recorder.log();
  return url.value_or("ws://127.0.0.1:1/");
}

std::vector<std::string> clientArguments(const std::string& url, bool withToken = true) {
  std::vector<std::string> arguments = {"--url", url};
  if (withToken) arguments.insert(arguments.end(), {"--token", kToken});
  return arguments;
}

// Messages of `topic` the client has printed so far.
std::vector<json> messagesOn(const FoxgloveClient& client, const std::string& topic) {
  std::vector<json> found;
  for (auto& event : client.events())
    if (event["event"] == "message" && event["topic"] == topic) found.push_back(event);
  return found;
}

size_t countOf(const FoxgloveClient& client, const std::string& topic) {
  return messagesOn(client, topic).size();
}

// The client drives /CAM/drive with `message` every 100 ms until stopped.
void startDriving(FoxgloveClient& client, const std::string& camera, const json& message) {
  client.command({{"cmd", "repeat"},
                  {"topic", "/" + camera + "/drive"},
                  {"message", message},
                  {"periodMs", 100}});
  ASSERT_TRUE(client.next("repeating", 5s));
}

void advertiseDrive(FoxgloveClient& client, const std::string& camera) {
  client.command({{"cmd", "advertise"},
                  {"topic", "/" + camera + "/drive"},
                  {"encoding", "json"},
                  {"schemaName", "wircam.Drive"}});
  ASSERT_TRUE(client.next("advertised", 5s));
}

// A followed car with a simulated Marvelmind dashboard reporting where it is.
struct PositionedCar : FollowedCar {
  std::unique_ptr<sim::MarvelmindDashboard> dashboard;
  PositionedCar() {
    auto running = sim::MarvelmindDashboard::start(
        {.beacons = {5}, .rate = 16, .noise = 0.01}, [s = scene.get()](size_t) {
          auto now = s->truthNow();
          return std::array<double, 3>{now.car.x, now.car.y, 0.25};
        });
    if (running) dashboard = std::move(*running);
  }
};

TEST(FoxgloveLive, AClientSeesTheCameraAsRecordedAndDrivesTheCar) {
  PositionedCar car;
  ASSERT_TRUE(car.device && car.dashboard);
  RecorderProcess recorder(
      car.device->port(),
      {"--detect", "tag36h11", "--follow", "--marvelmind",
       "127.0.0.1:" + std::to_string(car.dashboard->port()), "--beacon", "5", "--foxglove",
       "127.0.0.1:0", "--http-token", kToken, "--duration", "60"});
  std::string url = foxgloveUrl(recorder);
  std::string camera = cameraOf(car.device->port());
  std::string topic = "/" + camera;
  // As Foxglove opens it: the token in the URL.
  FoxgloveClient client({"--url", url + "?token=" + kToken});
  auto info = client.next("serverInfo", 10s);
  ASSERT_TRUE(info);
  EXPECT_EQ((*info)["capabilities"], json::array({"clientPublish"}));
  auto advertised = client.next("advertise", 5s);
  ASSERT_TRUE(advertised);
  std::map<std::string, json> channels;
  for (const auto& channel : (*advertised)["channels"]) channels[channel["topic"]] = channel;
  EXPECT_EQ(channels[topic + "/image"]["schemaName"], "foxglove.CompressedImage");
  EXPECT_EQ(channels[topic + "/tags"]["schemaName"], "foxglove.ImageAnnotations");
  EXPECT_EQ(channels[topic + "/pose"]["schemaName"], "foxglove.PoseInFrame");
  EXPECT_EQ(channels[topic + "/telemetry"]["encoding"], "json");
  EXPECT_EQ(channels[topic + "/log"]["schemaName"], "foxglove.Log");
  client.command({{"cmd", "subscribe"}, {"topics", "all"}});
  ASSERT_TRUE(client.next("subscribed", 10s));

  // Telemetry each second, and the rest as it comes.
  ASSERT_TRUE(waitFor([&] { return countOf(client, topic + "/telemetry") >= 3; }, 10s));
  EXPECT_TRUE(waitFor([&] { return countOf(client, topic + "/pose") >= 5; }, 5s));
  auto status = messagesOn(client, topic + "/telemetry").back()["decoded"];
  EXPECT_EQ(status["type"], "status");
  EXPECT_EQ(status["state"], "live");
  EXPECT_GT(status["fps"].get<double>(), 5);
  EXPECT_GT(status["battery_v"].get<double>(), 5);
  EXPECT_EQ(status["has_control"], true);
  EXPECT_EQ(status["following"], true);
  auto pose = messagesOn(client, topic + "/pose").back()["decoded"];
  auto truth = car.scene->truthNow().car;
  EXPECT_NEAR(pose["position"]["x"].get<double>(), truth.x, 0.5);
  EXPECT_NEAR(pose["position"]["y"].get<double>(), truth.y, 0.5);
  EXPECT_NEAR(pose["position"]["z"].get<double>(), 0.25, 0.1);
  EXPECT_EQ(pose["orientation"]["w"], 1);

  // Tags on the frames they were seen on: Foxglove draws an annotation on
  // the image of its timestamp.
  std::set<std::string> imageTimes;
  for (const auto& image : messagesOn(client, topic + "/image")) {
    EXPECT_EQ(image["decoded"]["format"], "jpeg");
    imageTimes.insert(image["timestamp"].get<std::string>());
  }
  size_t tagged = 0, onAnImage = 0;
  for (const auto& tags : messagesOn(client, topic + "/tags")) {
    if (tags["decoded"]["points"].empty()) continue;
    ++tagged;
    EXPECT_EQ(tags["decoded"]["texts"][0], "tag 0");
    onAnImage += imageTimes.contains(tags["timestamp"].get<std::string>()) ? 1 : 0;
  }
  EXPECT_GT(tagged, 10u);
  EXPECT_GE(onAnImage, tagged * 9 / 10) << onAnImage << " of " << tagged;

  // Drive: ahead and left as a Foxglove user publishes it; the car goes.
  advertiseDrive(client, camera);
  auto before = car.scene->truthNow().car;
  startDriving(client, camera, {{"steering", 1}, {"throttle", 1}});
  ASSERT_TRUE(waitFor([&] {
    auto pulses = car.device->outputs().pulses;
    return pulses[kThrottle] > 1500 && pulses[kSteering] > 1500;
  }));
  EXPECT_TRUE(waitFor([&] {
    auto now = car.scene->truthNow().car;
    return std::hypot(now.x - before.x, now.y - before.y) > 0.1 && now.theta > before.theta;
  }));
  // Foxglove's Teleop panel sends a Twist: ahead, turning right.
  client.command({{"cmd", "stopRepeat"}});
  ASSERT_TRUE(client.next("stoppedRepeat", 5s));
  startDriving(
      client, camera,
      {{"linear", {{"x", 0.5}, {"y", 0}, {"z", 0}}}, {"angular", {{"x", 0}, {"y", 0}, {"z", -1}}}});
  EXPECT_TRUE(waitFor([&] {
    auto pulses = car.device->outputs().pulses;
    return pulses[kThrottle] > 1500 && pulses[kSteering] < 1500;
  }));
  // Driving took the car from the follower, as the web page's drive mode
  // does: it stays where the driver leaves it.
  size_t statuses = countOf(client, topic + "/telemetry");
  ASSERT_TRUE(waitFor([&] { return countOf(client, topic + "/telemetry") > statuses; }, 3s));
  EXPECT_EQ(messagesOn(client, topic + "/telemetry").back()["decoded"]["following"], false);
  // The client falls silent, its socket open: the dead-man stops the car.
  client.command({{"cmd", "stopRepeat"}});
  ASSERT_TRUE(client.next("stoppedRepeat", 5s));
  auto silent = untilNeutral(*car.device);
  EXPECT_LE(silent.count(), 250 + 100 + 100) << "neutral " << silent.count() << " ms after";
  std::cerr << "[ measured ] silent Foxglove client → neutral in " << silent.count() << " ms\n";
  // Driving again, then junk: neutral at once, and that client is closed.
  startDriving(client, camera, {{"steering", 0}, {"throttle", 1}});
  ASSERT_TRUE(waitFor([&] { return car.device->outputs().pulses[kThrottle] > 1500; }));
  client.command({{"cmd", "publishText"}, {"topic", topic + "/drive"}, {"text", "{\"throttle\":"}});
  auto junk = untilNeutral(*car.device);
  EXPECT_LT(junk.count(), 250) << "neutral " << junk.count() << " ms after the junk";
  auto closed = client.next("close", 5s);
  ASSERT_TRUE(closed);
  EXPECT_EQ((*closed)["code"], 1008);
  EXPECT_NE((*closed)["reason"].get<std::string>().find("drive"), std::string::npos) << *closed;

  // A second client drives, then closes its socket: neutral at once.
  FoxgloveClient second(clientArguments(url));
  ASSERT_TRUE(second.next("advertise", 10s));
  advertiseDrive(second, camera);
  startDriving(second, camera, {{"steering", 0}, {"throttle", 1}});
  ASSERT_TRUE(waitFor([&] { return car.device->outputs().pulses[kThrottle] > 1500; }));
  second.command({{"cmd", "close"}});
  auto gone = untilNeutral(*car.device);
  EXPECT_LT(gone.count(), 250) << "neutral " << gone.count() << " ms after the close";

  // Every image was a frame of the recording, byte for byte.
  recorder.signal(SIGINT);
  ASSERT_EQ(recorder.waitExit(10s), 0) << recorder.log();
  std::set<std::string> recorded;
  for (const auto& file : recorder.files(".mkv"))
    for (auto& digest : frameDigests(file)) recorded.insert(digest);
  size_t images = 0, matched = 0;
  for (const auto& image : messagesOn(client, topic + "/image")) {
    ++images;
    matched += recorded.contains(image["decoded"]["md5"].get<std::string>()) ? 1 : 0;
  }
  EXPECT_GT(images, 30u);
  EXPECT_EQ(matched, images);
  for (const auto& event : client.events()) EXPECT_NE(event["event"], "decodeError") << event;
}

TEST(FoxgloveLive, TheTokenIsNeededAndDrivingNeedsOne) {
  auto device = startSequenceDevice();
  ASSERT_TRUE(device);
  {
    RecorderProcess recorder(
        device->port(), {"--foxglove", "127.0.0.1:0", "--http-token", kToken, "--duration", "60"});
    std::string url = foxgloveUrl(recorder);
    FoxgloveClient without(clientArguments(url, false));
    auto error = without.next("error", 10s);
    ASSERT_TRUE(error);
    EXPECT_NE((*error)["message"].get<std::string>().find("401"), std::string::npos) << *error;
    FoxgloveClient wrong({"--url", url, "--token", "not-the-token"});
    EXPECT_TRUE(wrong.next("error", 10s));
    // A plain HTTP request is told what the port is.
    auto plain =
        fetch("http" + url.substr(2), "GET", {{"Authorization", std::string("Bearer ") + kToken}});
    EXPECT_EQ(plain.status, 426u);
    EXPECT_NE(plain.body.find("Foxglove"), std::string::npos) << plain.body;
  }
  // Without a token the recorder serves this machine, and drives nothing.
  RecorderProcess recorder(device->port(), {"--foxglove", "127.0.0.1:0", "--duration", "60"});
  FoxgloveClient client(clientArguments(foxgloveUrl(recorder), false));
  auto info = client.next("serverInfo", 10s);
  ASSERT_TRUE(info);
  EXPECT_EQ((*info)["capabilities"], json::array());
  ASSERT_TRUE(client.next("advertise", 5s));
  advertiseDrive(client, cameraOf(device->port()));
  auto refused = client.next("status", 5s);
  ASSERT_TRUE(refused);
  EXPECT_EQ((*refused)["level"], 2);
  EXPECT_NE((*refused)["message"].get<std::string>().find("--http-token"), std::string::npos);
}

TEST(FoxgloveLive, OneClientTooManyIsToldWhyAndJunkClosesOnlyItsSender) {
  auto device = startSequenceDevice();
  ASSERT_TRUE(device);
  RecorderProcess recorder(device->port(),
                           {"--foxglove", "127.0.0.1:0", "--foxglove-max-clients", "2", "--http",
                            "127.0.0.1:0", "--http-token", kToken, "--duration", "60"});
  std::string url = foxgloveUrl(recorder);
  auto http = recorder.waitForLog("http://", 10s);
  ASSERT_TRUE(http);
  std::string topic = "/" + cameraOf(device->port()) + "/image";
  FoxgloveClient watcher(clientArguments(url));
  ASSERT_TRUE(watcher.next("advertise", 10s));
  watcher.command({{"cmd", "subscribe"}, {"topics", {topic}}});
  ASSERT_TRUE(watcher.next("subscribed", 10s));
  FoxgloveClient junk(clientArguments(url));
  ASSERT_TRUE(junk.next("advertise", 10s));
  {
    FoxgloveClient third(clientArguments(url));
    auto refused = third.next("status", 10s);
    ASSERT_TRUE(refused);
    EXPECT_EQ((*refused)["message"],
              "this recorder serves at most 2 Foxglove clients at once; try again later");
    auto closed = third.next("close", 5s);
    ASSERT_TRUE(closed);
    EXPECT_EQ((*closed)["code"], 1008);
    EXPECT_EQ((*closed)["reason"], "too many clients");
  }
  auto status = [&] {
    return nlohmann::json::parse(
        fetch(*http + "api/status", "GET", {{"Authorization", std::string("Bearer ") + kToken}})
            .body,
        nullptr, false);
  };
  EXPECT_EQ(status()["foxglove"]["refused"], 1);
  EXPECT_EQ(status()["foxglove"]["clients"], 2);
  // An op this server does not serve closes its sender, not the watcher.
  junk.command({{"cmd", "sendText"}, {"text", R"({"op":"fetchAsset","uri":"x","requestId":1})"}});
  auto closed = junk.next("close", 5s);
  ASSERT_TRUE(closed);
  EXPECT_EQ((*closed)["code"], 1008);
  EXPECT_EQ((*closed)["reason"], "op 'fetchAsset' is not served here");
  // So does a message far over the size any client needs.
  FoxgloveClient big(clientArguments(url));
  ASSERT_TRUE(big.next("advertise", 10s));
  big.command({{"cmd", "sendText"}, {"text", std::string(300 * 1024, ' ')}});
  auto tooBig = big.next("close", 5s);
  ASSERT_TRUE(tooBig);
  EXPECT_EQ((*tooBig)["code"], 1009) << *tooBig;
  EXPECT_EQ((*tooBig)["reason"], "a message of 307200 bytes; at most 262144");
  size_t seen = countOf(watcher, topic);
  EXPECT_TRUE(waitFor([&] { return countOf(watcher, topic) > seen + 10; }, 5s));
}

TEST(FoxgloveLive, AClientThatStopsReadingMissesFramesAndHoldsNothing) {
  // 640x480 frames, so that a paused reader's socket fills within seconds.
  auto device = startSequenceDevice(0, 30);
  ASSERT_TRUE(device);
  RecorderProcess recorder(device->port(), {"--foxglove", "127.0.0.1:0", "--http", "127.0.0.1:0",
                                            "--http-token", kToken, "--duration", "90"});
  std::string url = foxgloveUrl(recorder);
  auto http = recorder.waitForLog("http://", 10s);
  ASSERT_TRUE(http);
  std::string topic = "/" + cameraOf(device->port()) + "/image";
  FoxgloveClient watcher(clientArguments(url));
  FoxgloveClient stalled(clientArguments(url));
  for (auto* client : {&watcher, &stalled}) {
    ASSERT_TRUE(client->next("advertise", 10s));
    client->command({{"cmd", "subscribe"}, {"topics", {topic}}});
    ASSERT_TRUE(client->next("subscribed", 10s));
  }
  ASSERT_TRUE(waitFor([&] { return countOf(stalled, topic) > 30; }, 10s));
  stalled.command({{"cmd", "pauseReading"}});
  ASSERT_TRUE(stalled.next("paused", 5s));
  // Held nothing: a stalled reader costs the recorder a socket's worth.
  long residentBefore = residentKb(recorder.pid());
  auto metric = [&](const std::string& name) {
    auto text =
        fetch(*http + "metrics", "GET", {{"Authorization", std::string("Bearer ") + kToken}}).body;
    auto at = text.find("\n" + name + " ");
    return at == std::string::npos ? -1 : std::atoll(text.c_str() + at + name.size() + 2);
  };
  ASSERT_TRUE(waitFor([&] { return metric("wircam_foxglove_dropped_total") > 60; }, 30s))
      << metric("wircam_foxglove_dropped_total");
  // The watcher is not held back: 40 more frames come (at 30/s, well
  // within the wait) while the stalled one holds its socket full.
  size_t watched = countOf(watcher, topic);
  EXPECT_TRUE(waitFor([&] { return countOf(watcher, topic) > watched + 40; }, 10s));
  long residentAfter = residentKb(recorder.pid());
  if (!kAddressSanitizer) {
    EXPECT_LT(residentAfter - residentBefore, 8 * 1024) << residentBefore << " → " << residentAfter;
  }
  // Reading again, it gets the newest frames again.
  size_t before = countOf(stalled, topic);
  stalled.command({{"cmd", "resumeReading"}});
  EXPECT_TRUE(waitFor([&] { return countOf(stalled, topic) > before + 30; }, 10s));
}

}  // namespace

TEST(FoxgloveLive, AnH264RecordingIsServedAsFoxgloveDecodesIt) {
  auto device = startSequenceDevice();
  ASSERT_TRUE(device);
  RecorderProcess recorder(device->port(),
                           {"--codec", "h264", "--foxglove", "127.0.0.1:0", "--duration", "60"});
  std::string url = foxgloveUrl(recorder);
  std::string topic = "/" + cameraOf(device->port()) + "/image";
  fs::path stream = recorder.out().parent_path() / "live.h264";
  FoxgloveClient client({"--url", url, "--save-images", stream.string()});
  ASSERT_TRUE(client.next("advertise", 10s));
  client.command({{"cmd", "subscribe"}, {"topics", {topic}}});
  ASSERT_TRUE(client.next("subscribed", 10s));
  ASSERT_TRUE(waitFor([&] { return countOf(client, topic) >= 45; }, 15s));
  client.command({{"cmd", "close"}});
  ASSERT_TRUE(client.next("close", 5s));
  auto images = messagesOn(client, topic);
  for (const auto& image : images) EXPECT_EQ(image["decoded"]["format"], "h264");
  // Foxglove shows H.264 as video, not as an image.
  auto advertised = client.events();
  for (const auto& event : advertised) {
    if (event["event"] != "advertise") continue;
    for (const auto& channel : event["channels"])
      if (channel["topic"] == topic) {
        EXPECT_EQ(channel["schemaName"], "foxglove.CompressedVideo");
      }
  }
  // Annex B from the first image on, which is a key frame: its access unit
  // delimiter, then its SPS (once: x264 repeats it in the stream). The
  // images alone are a stream ffmpeg decodes, every one a frame.
  std::ifstream in(stream, std::ios::binary);
  std::string head(64, '\0');
  in.read(head.data(), 64);
  EXPECT_TRUE(head.starts_with(std::string("\0\0\0\1\x09", 5)));
  auto sps = head.find(std::string("\0\0\0\1\x67", 5));
  EXPECT_NE(sps, std::string::npos);
  EXPECT_EQ(head.find(std::string("\0\0\0\1\x67", 5), sps + 1), std::string::npos);
  EXPECT_EQ(ffmpegDecodeErrors(stream), "");
  EXPECT_EQ(decodedFrameCount(stream), std::to_string(images.size()) + "\n");
}

// A minute of twenty Foxglove clients connecting, subscribing to every
// channel and leaving after 0.2-1 s, as panels and tabs come and go.
TEST(FoxgloveChurn, TwentyClientsComingAndGoingForAMinuteLeaveNothingBehind) {
  auto device = startSequenceDevice();
  ASSERT_TRUE(device);
  RecorderProcess recorder(device->port(), {"--foxglove", "127.0.0.1:0", "--foxglove-max-clients",
                                            "32", "--duration", "120"});
  std::string url = foxgloveUrl(recorder);
  auto churn = [&](int seconds) {
    FoxgloveClient clients(
        {"churn", "--url", url, "--clients", "20", "--seconds", std::to_string(seconds)});
    auto summary = clients.next("churn", std::chrono::seconds(seconds + 30));
    EXPECT_EQ(clients.wait(5s), 0);
    return summary.value_or(json::object());
  };
  // Lines of the recorder's log holding `text`, now.
  auto count = [&](const std::string& text) {
    auto log = recorder.log();
    size_t n = 0;
    for (size_t at = log.find(text); at != std::string::npos; at = log.find(text, at + 1)) ++n;
    return n;
  };
  // Warmed up: what the first clients start (libsoup's, GLib's) stays. The
  // counts are taken once every one of them has left.
  churn(3);
  ASSERT_TRUE(waitFor([&] { return count(" left") == count(" connected ("); }, 5s));
  auto first = processCounts(recorder.pid());
  long residentFirst = residentKb(recorder.pid());
  auto summary = churn(60);
  EXPECT_GT(summary.value("connections", 0), 500) << summary;
  EXPECT_GT(summary.value("messages", 0), 5000) << summary;
  EXPECT_EQ(summary.value("errors", json::array()), json::array()) << summary;
  // Each client's socket went with it (the recording's files may be
  // between two segments: a descriptor more or less).
  ASSERT_TRUE(waitFor([&] { return processCounts(recorder.pid()).sockets <= first.sockets; }, 5s))
      << processCounts(recorder.pid()).sockets << " sockets, " << first.sockets << " before; "
      << count(" connected (") << " clients connected, " << count(" left") << " left";
  auto last = processCounts(recorder.pid());
  EXPECT_LE(last.descriptors, first.descriptors + 1);
  EXPECT_LE(last.threads, first.threads);
  long residentLast = residentKb(recorder.pid());
  std::cerr << "[ measured ] " << summary.value("connections", 0)
            << " Foxglove connections: recorder " << residentFirst / 1024 << " → "
            << residentLast / 1024 << " MB, " << first.threads << " → " << last.threads
            << " threads, " << first.descriptors << " → " << last.descriptors << " descriptors\n";
  if (!kAddressSanitizer) {
    EXPECT_LT(residentLast - residentFirst, 8 * 1024);
  }
}
