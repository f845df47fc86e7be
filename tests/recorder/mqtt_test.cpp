// wirc-recorder --mqtt and --on-segment-closed against a real mosquitto on
// a loopback port of its own, the simulated car, and real hook commands.
#include <gtest/gtest.h>
#include <signal.h>

#include <cstring>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <thread>

#include "devices/wirc/device.h"
#include "mqtt_broker.h"
#include "recorder_process.h"
#include "signed_in_page.h"
#include "simulated_device.h"
#include "test_certificates.h"
#include "wait_for.h"

namespace {

namespace fs = std::filesystem;
using namespace wircam;
using namespace wircam::testing;
using namespace std::chrono_literals;
using Json = nlohmann::json;

std::string streamOf(const wirc::Device& device) {
  return "127.0.0.1-" + std::to_string(device.port()) + "-cam0";
}

Json parsed(const MqttMessage& m) { return Json::parse(m.payload, nullptr, false); }

// The recorder said it is online (under the default prefix).
bool cameOnline(MqttProbe& probe) {
  return probe.waitFor(
      "wircam/available", [](auto& m) { return m.payload == "online"; }, 10s);
}

// A broker, the follow scene's car and a subscriber to everything under
// wircam/; follow() starts a recorder that follows the car and publishes
// there, and says whether it came online.
struct FollowedOverMqtt {
  MosquittoBroker broker;
  std::unique_ptr<wirc::Device> device = startFollowDevice();
  std::string stream = device ? streamOf(*device) : "";
  MqttProbe probe{broker.port(), "wircam/#"};
  std::unique_ptr<RecorderProcess> recorder;

  bool follow() {
    recorder = std::make_unique<RecorderProcess>(
        device->port(), std::vector<std::string>{"--detect", "tag36h11", "--follow", "--mqtt",
                                                 broker.url(), "--duration", "60"});
    return cameOnline(probe);
  }
};

TEST(RecorderMqtt, StatusRetainedDetectionsAndTheLastWillOnKill) {
  FollowedOverMqtt car;
  ASSERT_TRUE(car.broker.running() && car.device);
  ASSERT_TRUE(car.follow()) << car.recorder->log();
  // Detections of the simulator's tag, id 0, with centre and corners.
  ASSERT_TRUE(car.probe.waitFor(
      "wircam/" + car.stream + "/detections",
      [](auto& m) {
        auto d = parsed(m);
        return !d.is_discarded() && !d["tags"].empty() && d["tags"][0]["id"] == 0 &&
               d["tags"][0]["corners"].size() == 8 && d["tags"][0].contains("cx");
      },
      10s));
  ASSERT_TRUE(car.probe.waitFor(
      "wircam/" + car.stream + "/status",
      [](auto& m) {
        auto s = parsed(m);
        return m.retained == false && s["state"] == "live" && s["fps"].template get<double>() > 0 &&
               s["has_control"] == true && s["following"] == true && s.contains("loss") &&
               s.contains("battery_v") && s.contains("position");
      },
      10s));
  // Retained: a client that comes later gets the status and "online" at once.
  MqttProbe late(car.broker.port(), "wircam/#");
  EXPECT_TRUE(late.waitFor(
      "wircam/" + car.stream + "/status",
      [](auto& m) { return m.retained && parsed(m)["state"] == "live"; }, 5s));
  EXPECT_TRUE(late.waitFor(
      "wircam/available", [](auto& m) { return m.retained && m.payload == "online"; }, 5s));
  // kill -9: the broker says offline for it (the last will).
  car.recorder->signal(SIGKILL);
  car.recorder->wait();
  EXPECT_TRUE(late.waitFor(
      "wircam/available", [](auto& m) { return m.payload == "offline"; }, 5s));
}

TEST(RecorderMqtt, SegmentClosedForEveryFileAndTheHookGetsEachWhole) {
  MosquittoBroker broker;
  auto device = startSequenceDevice();
  ASSERT_TRUE(device);
  MqttProbe probe(broker.port(), "fleet/one/#");
  auto folder = fs::temp_directory_path() / ("wirc-hook-" + std::to_string(getpid()));
  fs::remove_all(folder);
  fs::create_directories(folder / "uploaded");
  // An uploader as a user would write one: copy the segment and its sidecar.
  auto hook = folder / "upload.sh";
  std::ofstream(hook) << "#!/bin/sh\nset -e\ncp \"$1\" \"$2\" '" << (folder / "uploaded").string()
                      << "/'\n";
  fs::permissions(hook, fs::perms::owner_all);
  RecorderProcess recorder(device->port(),
                           {"--mqtt", broker.url(), "--mqtt-prefix", "fleet/one", "--segment", "2",
                            "--duration", "7", "--on-segment-closed", hook.string()});
  ASSERT_EQ(recorder.wait(), 0) << recorder.log();
  auto files = recorder.files(".mkv");
  ASSERT_GE(files.size(), 3u);
  std::string stream = streamOf(*device);
  ASSERT_TRUE(probe.waitFor(
      "fleet/one/" + stream + "/events",
      [&](auto&) {
        size_t closed = 0;
        for (const auto& m : probe.messages("fleet/one/" + stream + "/events"))
          closed += parsed(m)["type"] == "segment-closed";
        return closed == files.size();
      },
      5s));
  for (const auto& m : probe.messages("fleet/one/" + stream + "/events")) {
    auto event = parsed(m);
    if (event["type"] != "segment-closed") continue;
    EXPECT_TRUE(fs::exists(recorder.out() / event["file"].get<std::string>())) << m.payload;
    EXPECT_GT(event["duration_s"].get<double>(), 0.5);
    EXPECT_EQ(event["start_utc"].get<std::string>().back(), 'Z');
  }
  for (const auto& file : files) {
    auto copy = folder / "uploaded" / file.filename();
    ASSERT_TRUE(fs::exists(copy)) << file;
    EXPECT_EQ(fs::file_size(copy), fs::file_size(file)) << file;
    std::string compare = "cmp -s '" + file.string() + "' '" + copy.string() + "'";
    EXPECT_EQ(std::system(compare.c_str()), 0) << file << " arrived changed";
    auto sidecar = fs::path(file).replace_extension(".jsonl");
    EXPECT_TRUE(fs::exists(folder / "uploaded" / sidecar.filename()));
  }
  fs::remove_all(folder);
}

TEST(RecorderMqtt, FollowOffSendsTheCarToNeutralWithinOneCommandPeriod) {
  FollowedOverMqtt car;
  ASSERT_TRUE(car.device);
  ASSERT_TRUE(car.follow()) << car.recorder->log();
  // Driving after the target.
  auto moving = [&] { return car.device->outputs().pulses[1] != wirc::kPulseNeutral; };
  for (int i = 0; i < 500 && !moving(); ++i) std::this_thread::sleep_for(10ms);
  ASSERT_TRUE(moving()) << "the car never drove";
  auto sent = std::chrono::steady_clock::now();
  car.probe.publish("wircam/" + car.stream + "/follow/set", "OFF");
  while (moving() && std::chrono::steady_clock::now() - sent < 2s) std::this_thread::sleep_for(1ms);
  auto took = std::chrono::steady_clock::now() - sent;
  EXPECT_FALSE(moving());
  // At once, not on a later frame's command: 18-20 ms idle (the broker, the
  // recorder, the link's pacing of PCDs); a frame at the simulator's 15 fps
  // is 67 ms. The bound is two frames: on two cores beside eight suites the
  // same path took 70 ms once.
  EXPECT_LT(took, 134ms) << std::chrono::duration_cast<std::chrono::milliseconds>(took).count();
  EXPECT_EQ(car.device->outputs().pulses[0], wirc::kPulseNeutral);  // steering too
  EXPECT_TRUE(car.probe.waitFor(
      "wircam/" + car.stream + "/status", [](auto& m) { return parsed(m)["following"] == false; },
      3s));
  // It stays stopped while the target is in view: five more commands (half
  // a second of keepalives) reach the car and it is still at neutral. ON
  // resumes.
  auto pcd = car.device->stats().pcdReceived;
  ASSERT_TRUE(waitFor([&] { return car.device->stats().pcdReceived >= pcd + 5; }));
  EXPECT_FALSE(moving());
  car.probe.publish("wircam/" + car.stream + "/follow/set", "ON");
  bool resumed = false;
  for (int i = 0; i < 300 && !resumed; ++i, std::this_thread::sleep_for(10ms)) resumed = moving();
  EXPECT_TRUE(resumed);
}

// Driving by hand over the broker, by the vehicle's serial (whichever
// recorder holds it): a stream of drive/set messages drives the car and
// takes it from the follower, as the page's drive mode does; when they stop,
// wirccontrol's dead-man (250 ms) stops it.
TEST(RecorderMqtt, DriveSetMessagesDriveTheCarAndTheirSilenceStopsIt) {
  FollowedOverMqtt car;
  ASSERT_TRUE(car.device);
  ASSERT_TRUE(car.follow()) << car.recorder->log();
  // The vehicle's identity is asked once the device is live.
  ASSERT_TRUE(car.probe.waitFor(
      "wircam/" + car.stream + "/status", [](auto& m) { return parsed(m)["vehicle"].is_object(); },
      10s));
  // A driver's stream of commands: one each time the car is looked at
  // (every 20 ms at most), as a joystick sends them.
  auto drive = [&] {
    car.probe.publish("wircam-fleet/vehicles/SIM0001/drive/set",
                      R"({"steering": 1, "throttle": 1})");
  };
  bool drove = waitFor([&] {
    drive();
    auto pulses = car.device->outputs().pulses;
    return pulses[kThrottle] > wirc::kPulseNeutral && pulses[kSteering] > wirc::kPulseNeutral;
  });
  bool tookFromFollower = car.probe.waitFor(
      "wircam/" + car.stream + "/status", [](auto& m) { return parsed(m)["following"] == false; },
      5s);
  drive();  // the last one: the dead-man counts from here
  ASSERT_TRUE(drove) << car.recorder->log();
  EXPECT_TRUE(tookFromFollower);
  auto silent = untilNeutral(*car.device);
  // The dead-man, the broker's hop and the polling.
  EXPECT_LE(silent.count(), 250 + 100 + 100) << "neutral " << silent.count() << " ms after";
  // A message it cannot take is said once, and leaves the car as it is.
  car.probe.publish("wircam/" + car.stream + "/drive/set", R"({"steering": 3, "throttle": 0})");
  EXPECT_TRUE(car.recorder->waitForText("drive/set: ", 5s)) << car.recorder->log();
  EXPECT_EQ(car.device->outputs().pulses[kThrottle], wirc::kPulseNeutral);
}

TEST(RecorderMqtt, RejoinsABrokerRestartedMidRun) {
  MosquittoBroker broker;
  auto device = startSequenceDevice();
  ASSERT_TRUE(device);
  RecorderProcess recorder(device->port(), {"--mqtt", broker.url(), "--duration", "60"});
  {
    MqttProbe probe(broker.port(), "wircam/#");
    ASSERT_TRUE(cameOnline(probe));
  }
  broker.kill();
  // The recorder notices and backs off.
  ASSERT_TRUE(recorder.waitForText("lost the MQTT broker", 10s)) << recorder.log();
  ASSERT_TRUE(broker.start());
  MqttProbe probe(broker.port(), "wircam/#");
  // Back within its backoff (a few seconds), with its retained status again.
  EXPECT_TRUE(cameOnline(probe)) << recorder.log();
  EXPECT_TRUE(probe.waitFor(
      "wircam/" + streamOf(*device) + "/status",
      [](auto& m) { return parsed(m)["state"] == "live"; }, 10s));
  EXPECT_NE(recorder.log().find("lost the MQTT broker"), std::string::npos) << recorder.log();
  recorder.signal(SIGTERM);
  EXPECT_EQ(recorder.wait(), 0);
}

TEST(RecorderMqtt, RecordsOnWhateverTheBrokerDoes) {
  // Down at the start, then refusing the credentials: clear lines, and the
  // recording goes on.
  MosquittoBroker strict("rover", "secret");
  ASSERT_TRUE(strict.running());
  auto device = startSequenceDevice();
  ASSERT_TRUE(device);
  RecorderProcess wrongPassword(device->port(),
                                {"--mqtt", strict.url("rover:wrong"), "--duration", "4"});
  RecorderProcess nobody(device->port(), {"--mqtt", "mqtt://127.0.0.1:1", "--duration", "4"});
  EXPECT_EQ(wrongPassword.wait(), 0) << wrongPassword.log();
  EXPECT_EQ(nobody.wait(), 0) << nobody.log();
  EXPECT_NE(wrongPassword.log().find("refused the connection: Connection Refused: not authorised"),
            std::string::npos)
      << wrongPassword.log();
  EXPECT_NE(nobody.log().find("cannot be reached"), std::string::npos) << nobody.log();
  EXPECT_FALSE(wrongPassword.files(".mkv").empty());
  EXPECT_FALSE(nobody.files(".mkv").empty());
  // The right password works.
  MqttProbe watcher(strict.port(), "#");  // anonymous: refused, sees nothing
  RecorderProcess right(device->port(), {"--mqtt", strict.url("rover:secret"), "--duration", "3"});
  EXPECT_EQ(right.wait(), 0);
  EXPECT_NE(right.log().find("connected to the MQTT broker"), std::string::npos) << right.log();
}

TEST(RecorderMqtt, IgnoresRetainedJunkAndBadCommands) {
  FollowedOverMqtt car;
  ASSERT_TRUE(car.device);
  // Left behind by some other tool: replayed to every new subscriber.
  car.probe.publish("wircam/" + car.stream + "/follow/set", "OFF", true);
  car.probe.publish("wircam/" + car.stream + "/target/set", "\x01\xff junk", true);
  // Back to the probe itself: the broker holds them.
  ASSERT_TRUE(car.probe.waitFor(
      "wircam/" + car.stream + "/target/set", [](auto& m) { return !m.payload.empty(); }, 5s));
  ASSERT_TRUE(car.follow()) << car.recorder->log();
  car.probe.publish("wircam/" + car.stream + "/follow/set", "SIDEWAYS");
  car.probe.publish("wircam/" + car.stream + "/target/set", "7x");
  car.probe.publish("wircam/no-such-stream/follow/set", "OFF");
  // All three refused (the last sent is the last refused).
  ASSERT_TRUE(car.recorder->waitForText("no stream 'no-such-stream'", 10s)) << car.recorder->log();
  // Still following: no junk turned it off.
  EXPECT_TRUE(car.probe.waitFor(
      "wircam/" + car.stream + "/status", [](auto& m) { return parsed(m)["following"] == true; },
      5s));
  for (const auto& m : car.probe.messages("wircam/" + car.stream + "/status"))
    EXPECT_EQ(parsed(m)["following"], true) << m.payload;
  auto log = car.recorder->log();
  EXPECT_NE(log.find("ignoring the retained message on wircam/" + car.stream + "/follow/set"),
            std::string::npos)
      << log;
  EXPECT_NE(log.find("follow/set takes ON or OFF, not 'SIDEWAYS'"), std::string::npos) << log;
  EXPECT_NE(log.find("not '7x'"), std::string::npos) << log;
  EXPECT_NE(log.find("no stream 'no-such-stream'"), std::string::npos) << log;
  // Clean up the retained ones.
  car.probe.publish("wircam/" + car.stream + "/follow/set", "", true);
}

TEST(RecorderMqtt, PeerTextInCommandsCannotForgeOrCutLogLines) {
  FollowedOverMqtt car;
  ASSERT_TRUE(car.device);
  ASSERT_TRUE(car.follow()) << car.recorder->log();
  std::string follow = "wircam/" + car.stream + "/follow/set";
  car.probe.publish(follow, "ON\nwirc-recorder: FORGED LINE");
  car.probe.publish(follow,
                    "\x1B[2J\x9B"
                    "31mred");
  car.probe.publish(follow, std::string("ON\0OFF", 6));
  // The last one, whole: the zero byte no longer ends the line.
  ASSERT_TRUE(
      waitFor([&] { return car.recorder->log().find("ON\\x00OFF") != std::string::npos; }, 10s))
      << car.recorder->log();
  auto log = car.recorder->log();
  EXPECT_EQ(log.find("\nwirc-recorder: FORGED"), std::string::npos) << log;
  EXPECT_NE(log.find("not 'ON\\x0Awirc-recorder: FORGED LINE'"), std::string::npos) << log;
  EXPECT_NE(log.find("not '\\x1B[2J\\x9B31mred'"), std::string::npos) << log;
  EXPECT_EQ(log.find('\x1B'), std::string::npos) << log;
}

TEST(RecorderMqtt, AHangingHookIsStoppedRetriedAndReportedWhileRecordingGoesOn) {
  MosquittoBroker broker;
  auto device = startSequenceDevice();
  ASSERT_TRUE(device);
  MqttProbe probe(broker.port(), "wircam/#");
  auto hang = fs::temp_directory_path() / ("wirc-hang-" + std::to_string(getpid()) + ".sh");
  std::ofstream(hang) << "#!/bin/sh\nsleep 1000\n";
  fs::permissions(hang, fs::perms::owner_all);
  auto start = std::chrono::steady_clock::now();
  RecorderProcess recorder(device->port(), {"--mqtt", broker.url(), "--segment", "2", "--duration",
                                            "5", "--on-segment-closed", hang.string(),
                                            "--hook-timeout", "1", "--hook-drain", "2"});
  EXPECT_EQ(recorder.wait(), 0) << recorder.log();
  // Recording was not held up: the segments are all there and whole, and
  // the exit came after at most the hooks' drain time.
  EXPECT_GE(recorder.files(".mkv").size(), 2u);
  EXPECT_LT(std::chrono::steady_clock::now() - start, 30s);
  EXPECT_NE(recorder.log().find("ran longer than 1 s"), std::string::npos) << recorder.log();
  EXPECT_NE(recorder.log().find("did not get to"), std::string::npos) << recorder.log();
  EXPECT_EQ(recorder.log().find("gave up waiting for the pipeline"), std::string::npos)
      << recorder.log();
  fs::remove(hang);
  EXPECT_TRUE(probe.waitFor(
      "wircam/" + streamOf(*device) + "/events",
      [](auto& m) { return parsed(m)["type"] == "hook-failed"; }, 3s));
}

}  // namespace

namespace {

// mqtts://: the recorder joins a TLS listener with the test's CA and
// publishes over it; with a CA that did not sign the broker's certificate
// it says why and records on.
TEST(RecorderMqttTls, JoinsATlsBrokerWithItsCaAndRefusesAnotherCa) {
  fs::path certificates = fs::temp_directory_path() / ("wirc-mqtts-" + std::to_string(getpid()));
  fs::path stranger = certificates / "stranger";
  ASSERT_TRUE(makeCertificates(certificates));
  ASSERT_TRUE(makeCertificates(stranger));  // another CA altogether
  MosquittoBroker broker("", "", certificates);
  ASSERT_TRUE(broker.running());
  MqttProbe probe(broker.port(), "wircam/#");
  auto device = startSequenceDevice();
  std::string tlsUrl = "mqtts://127.0.0.1:" + std::to_string(broker.tlsPort());
  RecorderProcess trusted(device->port(), {"--mqtt", tlsUrl, "--mqtt-cafile",
                                           (certificates / "ca.pem").string(), "--duration", "30"});
  std::string stream = "127.0.0.1-" + std::to_string(device->port()) + "-cam0";
  EXPECT_TRUE(probe.waitFor(
      "wircam/" + stream + "/status", [](auto& m) { return parsed(m)["state"] == "live"; }, 10s))
      << trusted.log();

  RecorderProcess refused(device->port(),
                          {"--mqtt", tlsUrl, "--mqtt-cafile", (stranger / "ca.pem").string(),
                           "--segment", "1", "--duration", "30"});
  EXPECT_TRUE(refused.waitForText("the TLS handshake failed", 10000ms)) << refused.log();
  EXPECT_TRUE(waitFor([&] { return refused.files(".mkv").size() >= 2; }, 10000ms)) << "records on";
  fs::remove_all(certificates);
}

}  // namespace

namespace {

// --mqtt-discovery: Home Assistant's retained configs for the camera as one
// device, each with a unique id and topics that work; a config left by a
// camera no longer here is cleared.
TEST(RecorderMqttDiscovery, HomeAssistantFindsTheCameraAndItsControlsWork) {
  FollowedOverMqtt car;
  ASSERT_TRUE(car.broker.running() && car.device);
  MqttProbe assistant(car.broker.port(), "homeassistant/#");
  // Left by an earlier run with a camera that is gone.
  std::string stale = "homeassistant/sensor/wircam_wircam/rover-gone-cam0_battery/config";
  assistant.publish(stale, R"({"unique_id":"wircam_rover-gone-cam0_battery"})", true);
  // Held by the broker and heard by this probe before the recorder starts:
  // otherwise the recorder may clear it before the probe listens.
  ASSERT_TRUE(assistant.waitFor(
      stale, [](auto& m) { return !m.payload.empty(); }, 10s));
  car.recorder = std::make_unique<RecorderProcess>(
      car.device->port(),
      std::vector<std::string>{"--detect", "tag36h11", "--follow", "--mqtt", car.broker.url(),
                               "--mqtt-discovery", "--mqtt-snapshot-interval", "1", "--duration",
                               "60"});
  ASSERT_TRUE(cameOnline(car.probe)) << car.recorder->log();
  std::string id = car.stream;
  for (char& c : id)
    if (c == '.') c = '_';
  std::map<std::string, Json> configs;
  for (const char* entity : {"camera/camera", "switch/following", "number/target", "sensor/battery",
                             "sensor/fps", "sensor/loss", "binary_sensor/connectivity"}) {
    std::string component(entity, std::strchr(entity, '/'));
    std::string key = std::strchr(entity, '/') + 1;
    std::string topic =
        "homeassistant/" + component + "/wircam_wircam/" + id + "_" + key + "/config";
    ASSERT_TRUE(assistant.waitFor(
        topic, [](auto& m) { return !m.payload.empty(); }, 10s))
        << topic;
    auto config = parsed(assistant.messages(topic).back());
    ASSERT_TRUE(config.is_object()) << topic;
    EXPECT_EQ(config["unique_id"], "wircam_" + id + "_" + key);
    EXPECT_EQ(config["device"]["identifiers"][0], "wircam_" + id);
    EXPECT_EQ(config["availability_topic"], "wircam/available");
    configs[key] = config;
  }
  // Retained: Home Assistant started later finds them.
  MqttProbe later(car.broker.port(), "homeassistant/switch/#");
  EXPECT_TRUE(later.waitFor(
      "homeassistant/switch/wircam_wircam/" + id + "_following/config",
      [](auto& m) { return m.retained; }, 10s));
  // The stale config is cleared with an empty retained message.
  EXPECT_TRUE(assistant.waitFor(
      stale, [](auto& m) { return m.payload.empty(); }, 10s))
      << [&] {
           std::string seen;
           for (auto& m : assistant.messages(stale))
             seen += "[" + m.payload + (m.retained ? " retained" : "") + "] ";
           return seen;
         }();

  // The camera entity's topic carries the camera's JPEG.
  std::string snapshot = configs["camera"]["topic"];
  EXPECT_TRUE(car.probe.waitFor(
      snapshot,
      [](auto& m) { return m.payload.size() > 1000 && m.payload.starts_with("\xFF\xD8"); }, 10s));
  // The switch: its command topic turns following off, its state says so.
  ASSERT_TRUE(car.probe.waitFor(
      configs["following"]["state_topic"], [](auto& m) { return parsed(m)["following"] == true; },
      10s));
  car.probe.publish(configs["following"]["command_topic"], configs["following"]["payload_off"]);
  EXPECT_TRUE(car.probe.waitFor(
      configs["following"]["state_topic"], [](auto& m) { return parsed(m)["following"] == false; },
      10s));
  // The number: a target id in, the state's target out.
  car.probe.publish(configs["target"]["command_topic"], "7");
  EXPECT_TRUE(car.probe.waitFor(
      configs["target"]["state_topic"], [](auto& m) { return parsed(m)["target"] == 7; }, 10s));
}

}  // namespace
