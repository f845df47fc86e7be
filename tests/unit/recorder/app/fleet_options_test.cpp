// The fleet options (--mqtt, --on-segment-closed, --marvelmind) and their
// errors.
#include <gtest/gtest.h>

#include "app/recorder_options.h"

namespace wircam::recorder {
namespace {

Expected<RecorderOptions, std::string> parse(std::vector<std::string> words) {
  words.insert(words.begin(), {"wirc-recorder", "--out", "/tmp/x", "--device", "127.0.0.1"});
  std::vector<char*> argv;
  for (auto& word : words) argv.push_back(word.data());
  argv.push_back(nullptr);
  return parseOptions(static_cast<int>(words.size()), argv.data());
}

TEST(FleetOptions, MqttPrefixHookAndTheirErrors) {
  auto options = parse({"--mqtt", "mqtt://127.0.0.1:1883", "--mqtt-prefix", "lab/node-a",
                        "--on-segment-closed", "upload --to 'my bucket'", "--hook-timeout", "30",
                        "--hook-drain", "2.5"});
  ASSERT_TRUE(options) << options.error();
  EXPECT_EQ(*options->mqtt, "mqtt://127.0.0.1:1883");
  EXPECT_EQ(options->mqttPrefix, "lab/node-a");
  // Split like a shell would, quotes and all, but no shell runs it.
  EXPECT_EQ(options->onSegmentClosed, (std::vector<std::string>{"upload", "--to", "my bucket"}));
  EXPECT_EQ(options->hookTimeoutSeconds, 30);
  EXPECT_EQ(options->hookDrainSeconds, 2.5);
  EXPECT_FALSE(parse({"--mqtt", "tcp://x"}));
  EXPECT_FALSE(parse({"--mqtt-prefix", "a/#"}));
  EXPECT_FALSE(parse({"--mqtt-prefix", "/a"}));
  EXPECT_FALSE(parse({"--on-segment-closed", "upload 'unclosed"}));
  EXPECT_FALSE(parse({"--hook-timeout", "0"}));
  EXPECT_FALSE(parse({"--hook-drain", "-1"}));
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
