// The MQTT URL and the commands taken over MQTT.
#include <gtest/gtest.h>

#include "fleet/fleet_command.h"
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
  for (const char* bad : {"", "-2", "7x", "1e3", "99999999999"})
    EXPECT_FALSE(parseFleetCommand("s", "target/set", bad)) << bad;
  EXPECT_FALSE(parseFleetCommand("s", "speed/set", "3"));
}

}  // namespace
}  // namespace wircam::recorder
