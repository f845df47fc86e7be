// The MQTT URL, the commands taken over MQTT, and Home Assistant's discovery.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "fleet/fleet_command.h"
#include "fleet/home_assistant.h"
#include "fleet/mqtt_url.h"

namespace wircam::recorder {
namespace {

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
  EXPECT_FALSE(plain->tls);
  auto secure = parseMqttUrl("mqtts://broker.lab");
  ASSERT_TRUE(secure);
  EXPECT_TRUE(secure->tls);
  EXPECT_EQ(secure->port, 8883);
  EXPECT_EQ(parseMqttUrl("mqtts://u:p@broker.lab:9883")->port, 9883);
  for (const char* bad : {"10.0.0.2", "http://x", "mqtt://", "mqtt://x:0", "mqtt://x:99999",
                          "mqtt://x:1883junk", "mqtt://a b", "mqttss://x", "mqtts://"})
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
  EXPECT_EQ(parseFleetCommand("s", "target/set", "65535")->target, 65535);
  // Past wirccontrol's target-id (65535) a command was taken, answered 200
  // and never obeyed (a stranger's trial): refused.
  for (const char* bad : {"", "-2", "7x", "1e3", "65536", "70000", "99999999999"})
    EXPECT_FALSE(parseFleetCommand("s", "target/set", bad)) << bad;
  EXPECT_EQ(parseFleetCommand("s", "target/set", "70000").error(),
            "a target is a tag id 0..65535 (or -1: the largest), not '70000'");
  EXPECT_FALSE(parseFleetCommand("s", "speed/set", "3"));
}

}  // namespace
}  // namespace wircam::recorder

namespace wircam::recorder {
namespace {

TEST(HomeAssistantDiscovery, EachCameraIsOneDeviceWithSevenEntitiesOnTheRecordersTopics) {
  DiscoveryNames names{.discoveryPrefix = "homeassistant", .topicPrefix = "lab/a", .version = "1"};
  auto configs = discoveryConfigs(names, "10.0.0.5-cam0");
  ASSERT_EQ(configs.size(), 7u);
  EXPECT_EQ(configs[1].first, "homeassistant/switch/wircam_lab_a/10_0_0_5-cam0_following/config");
  auto following = nlohmann::json::parse(configs[1].second);
  EXPECT_EQ(following["command_topic"], "lab/a/10.0.0.5-cam0/follow/set");
  EXPECT_EQ(following["state_topic"], "lab/a/10.0.0.5-cam0/status");
  EXPECT_EQ(following["availability_topic"], "lab/a/available");
  EXPECT_EQ(following["device"]["identifiers"][0], "wircam_10_0_0_5-cam0");
  EXPECT_EQ(discoverySubscription(names), "homeassistant/+/wircam_lab_a/+/config");
}

TEST(HomeAssistantDiscovery, OnlyThisRecordersConfigsOfCamerasItNoLongerHasAreStale) {
  DiscoveryNames names{.discoveryPrefix = "homeassistant", .topicPrefix = "wircam"};
  std::vector<std::string> streams = {"rover-cam0"};
  EXPECT_FALSE(
      isStaleConfig(names, "homeassistant/sensor/wircam_wircam/rover-cam0_fps/config", streams));
  EXPECT_TRUE(
      isStaleConfig(names, "homeassistant/sensor/wircam_wircam/rover-cam1_fps/config", streams));
  EXPECT_FALSE(
      isStaleConfig(names, "homeassistant/sensor/other_node/rover-cam1_fps/config", streams));
  EXPECT_FALSE(
      isStaleConfig(names, "elsewhere/sensor/wircam_wircam/rover-cam1_fps/config", streams));
}

}  // namespace
}  // namespace wircam::recorder
