// The fleet options (--mqtt, --on-segment-closed, --marvelmind), the MQTT
// URL and the commands taken over MQTT.
#include <gtest/gtest.h>

#include "app/recorder_options.h"
#include "fleet/fleet_command.h"
#include "fleet/mqtt_url.h"

namespace wircam::recorder {
namespace {

Expected<RecorderOptions, std::string> parse(std::vector<std::string> words) {
  words.insert(words.begin(), {"wirc-recorder", "--out", "/tmp/x", "--device", "127.0.0.1"});
  std::vector<char*> argv;
  for (auto& word : words) argv.push_back(word.data());
  argv.push_back(nullptr);
  return parseOptions(static_cast<int>(words.size()), argv.data());
}

TEST(MqttUrl, ReadsHostPortAndEscapedCredentials) {
  auto url = parseMqttUrl("mqtt://rec%40lab:p%3Ass@broker.lab:1884");
  ASSERT_TRUE(url) << url.error();
  EXPECT_EQ(url->host, "broker.lab");
  EXPECT_EQ(url->port, 1884);
  EXPECT_EQ(url->user, "rec@lab");
  EXPECT_EQ(url->password, "p:ss");
  auto plain = parseMqttUrl("mqtt://10.0.0.2");
  ASSERT_TRUE(plain);
  EXPECT_EQ(plain->port, 1883);
  EXPECT_TRUE(plain->user.empty());
  for (const char* bad : {"10.0.0.2", "http://x", "mqtt://", "mqtt://x:0", "mqtt://x:99999",
                          "mqtt://x:1883junk", "mqtt://a b"})
    EXPECT_FALSE(parseMqttUrl(bad)) << bad;
}

TEST(FleetCommand, TakesOnOffAndTagIdsAndNamesWhatItRefuses) {
  auto on = parseFleetCommand("rover-cam0", "follow/set", "ON");
  ASSERT_TRUE(on);
  EXPECT_EQ(on->kind, FleetCommand::Kind::kFollow);
  EXPECT_TRUE(on->follow);
  EXPECT_FALSE(parseFleetCommand("s", "follow/set", "off")->follow);
  auto target = parseFleetCommand("s", "target/set", "-1");
  ASSERT_TRUE(target);
  EXPECT_EQ(target->kind, FleetCommand::Kind::kTarget);
  EXPECT_EQ(target->target, -1);
  EXPECT_EQ(parseFleetCommand("s", "target/set", "42")->target, 42);
  EXPECT_EQ(parseFleetCommand("s", "follow/set", "MAYBE").error(),
            "follow/set takes ON or OFF, not 'MAYBE'");
  for (const char* bad : {"", "-2", "7x", "1e3", "99999999999"})
    EXPECT_FALSE(parseFleetCommand("s", "target/set", bad)) << bad;
  EXPECT_FALSE(parseFleetCommand("s", "speed/set", "3"));
}

TEST(FleetOptions, MqttPrefixHookAndTheirErrors) {
  auto options = parse({"--mqtt", "mqtt://127.0.0.1:1883", "--mqtt-prefix", "lab/node-a",
                        "--on-segment-closed", "upload --to 'my bucket'", "--hook-timeout", "30"});
  ASSERT_TRUE(options) << options.error();
  EXPECT_EQ(*options->mqtt, "mqtt://127.0.0.1:1883");
  EXPECT_EQ(options->mqttPrefix, "lab/node-a");
  // Split like a shell would, quotes and all, but no shell runs it.
  EXPECT_EQ(options->onSegmentClosed, (std::vector<std::string>{"upload", "--to", "my bucket"}));
  EXPECT_EQ(options->hookTimeoutSeconds, 30);
  EXPECT_FALSE(parse({"--mqtt", "tcp://x"}));
  EXPECT_FALSE(parse({"--mqtt-prefix", "a/#"}));
  EXPECT_FALSE(parse({"--mqtt-prefix", "/a"}));
  EXPECT_FALSE(parse({"--on-segment-closed", "upload 'unclosed"}));
  EXPECT_FALSE(parse({"--hook-timeout", "0"}));
  EXPECT_FALSE(parse({"--mqtt-detections-rate", "-1"}));
}

TEST(FleetOptions, MarvelmindNeedsItsBeaconAndTheOtherWayRound) {
  auto options = parse({"--marvelmind", "10.0.0.9", "--beacon", "6,5"});
  ASSERT_TRUE(options) << options.error();
  ASSERT_TRUE(options->devices[0].positions);
  EXPECT_EQ(options->devices[0].positions->host, "10.0.0.9");
  EXPECT_EQ(options->devices[0].positions->port, 49200);
  EXPECT_EQ(options->devices[0].positions->beacons, "6,5");
  EXPECT_FALSE(parse({"--marvelmind", "10.0.0.9"}));
  EXPECT_FALSE(parse({"--beacon", "5"}));
  EXPECT_FALSE(parse({"--marvelmind", "10.0.0.9:0", "--beacon", "5"}));
  EXPECT_FALSE(parse({"--marvelmind", "10.0.0.9", "--beacon", "255"}));
}

}  // namespace
}  // namespace wircam::recorder
