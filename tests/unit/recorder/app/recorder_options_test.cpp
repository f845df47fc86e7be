// wirc-recorder's command line: the new options and their errors.
#include "app/recorder_options.h"

#include <gtest/gtest.h>

#include "command_line.h"
#include "wirc/transmitter_session.h"

namespace wircam::recorder {
namespace {

TEST(RecorderOptions, ServersListenOnThisMachineUnlessAHostIsGiven) {
  auto options = parse({"--out", "x", "--http", ":8080", "--rtsp", "0.0.0.0:8554"});
  ASSERT_TRUE(options.has_value()) << options.error();
  EXPECT_EQ(options->http->listenHost(), "127.0.0.1");
  EXPECT_EQ(options->rtsp->listenHost(), "0.0.0.0");
}

TEST(RecorderOptions, TakesLoginChannelListsTheDeviceWouldAccept) {
  auto options = parse({"--out", "x", "--periods", "15000", "--failsafe", "1400"});
  ASSERT_TRUE(options.has_value()) << options.error();
  EXPECT_EQ(*options->periods, "15000");
  EXPECT_EQ(*options->failsafe, "1400");
}

TEST(RecorderOptions, TheLoginsOwnValuesWrittenOutAreNoSetting) {
  // So a config that spells out the default changes no camera's pipeline
  // (a reload would restart every camera for it).
  auto defaults = wirc::SessionConfig{};
  std::string periods = std::to_string(defaults.periods[0]);
  std::string failsafe;
  for (auto value : defaults.failsafe)
    failsafe += (failsafe.empty() ? "" : ",") + std::to_string(value);
  auto options = parse({"--out", "x", "--periods", periods, "--failsafe", failsafe});
  ASSERT_TRUE(options.has_value()) << options.error();
  EXPECT_FALSE(options->periods) << *options->periods;
  EXPECT_FALSE(options->failsafe) << *options->failsafe;
}

TEST(RecorderOptions, RefusesChannelListsTheDeviceWouldRefuseNamingTheProblem) {
  auto periods = parse({"--out", "x", "--periods", "100"});
  ASSERT_FALSE(periods.has_value());
  EXPECT_NE(periods.error().find("--periods"), std::string::npos) << periods.error();
  EXPECT_NE(periods.error().find("CCFG"), std::string::npos) << periods.error();
  auto failsafe = parse({"--out", "x", "--failsafe", "1500,1500"});
  ASSERT_FALSE(failsafe.has_value());
  EXPECT_NE(failsafe.error().find("give 1"), std::string::npos) << failsafe.error();
}

TEST(RecorderOptions, IdleTimeoutIsInSeconds) {
  auto options = parse({"--out", "x", "--http-idle-timeout", "2.5"});
  ASSERT_TRUE(options.has_value()) << options.error();
  EXPECT_DOUBLE_EQ(options->httpIdleSeconds, 2.5);
  EXPECT_FALSE(parse({"--out", "x", "--http-idle-timeout", "0"}).has_value());
}

TEST(RecorderOptions, TheTelemetryTrackIsOnUnlessTurnedOff) {
  auto byDefault = parse({"--out", "x"});
  ASSERT_TRUE(byDefault.has_value()) << byDefault.error();
  EXPECT_TRUE(byDefault->telemetryTrack);
  auto off = parse({"--out", "x", "--telemetry-track", "off"});
  ASSERT_TRUE(off.has_value()) << off.error();
  EXPECT_FALSE(off->telemetryTrack);
  auto neither = parse({"--out", "x", "--telemetry-track", "no"});
  ASSERT_FALSE(neither.has_value());
  EXPECT_EQ(neither.error(), "--telemetry-track: on or off");
}

TEST(RecorderOptions, FollowTuningTakesTheFollowersGainsWithinTheirRanges) {
  auto options = parse({"--out", "x", "--detect", "tag36h11", "--follow", "--follow-tuning",
                        "steering-kp=1.25,max-throttle=0.5"});
  ASSERT_TRUE(options.has_value()) << options.error();
  EXPECT_EQ(options->followTuning, " steering-kp=1.25 max-throttle=0.5");
  auto unknown = parse({"--out", "x", "--detect", "tag36h11", "--follow", "--follow-tuning",
                        "host=evil ! filesink location=/etc/passwd"});
  ASSERT_FALSE(unknown.has_value());
  EXPECT_NE(unknown.error().find("'host' is not one of steering-kp"), std::string::npos)
      << unknown.error();
  auto outside = parse(
      {"--out", "x", "--detect", "tag36h11", "--follow", "--follow-tuning", "max-throttle=2"});
  ASSERT_FALSE(outside.has_value());
  EXPECT_EQ(outside.error(), "--follow-tuning: max-throttle takes a number in 0..1");
  auto injected = parse({"--out", "x", "--detect", "tag36h11", "--follow", "--follow-tuning",
                         "steering-kp=1 ! fakesink"});
  EXPECT_FALSE(injected.has_value());
  auto alone = parse({"--out", "x", "--follow-tuning", "steering-kp=1"});
  ASSERT_FALSE(alone.has_value());
  EXPECT_NE(alone.error().find("needs --follow"), std::string::npos) << alone.error();
}

TEST(RecorderOptions, MqttDiscoveryTakesItsPrefixAsTheNextWordOrAfterAnEqualsSign) {
  const std::string mqtt = "mqtt://127.0.0.1";
  auto alone = parse({"--out", "x", "--mqtt", mqtt, "--mqtt-discovery"});
  ASSERT_TRUE(alone.has_value()) << alone.error();
  EXPECT_EQ(*alone->mqttDiscovery, "homeassistant");
  auto word = parse({"--mqtt-discovery", "ha2", "--out", "x", "--mqtt", mqtt});
  ASSERT_TRUE(word.has_value()) << word.error();
  EXPECT_EQ(*word->mqttDiscovery, "ha2");
  auto equals = parse({"--out", "x", "--mqtt", mqtt, "--mqtt-discovery=ha3"});
  ASSERT_TRUE(equals.has_value()) << equals.error();
  EXPECT_EQ(*equals->mqttDiscovery, "ha3");
  auto followed = parse({"--mqtt-discovery", "--out", "x", "--mqtt", mqtt});
  ASSERT_TRUE(followed.has_value()) << followed.error();
  EXPECT_EQ(*followed->mqttDiscovery, "homeassistant");
  EXPECT_FALSE(parse({"--out", "x", "--mqtt-discovery"}).has_value());  // needs --mqtt
}

TEST(RecorderOptions, RefusesNumbersNoFieldCanHold) {
  // Found by fuzz_recorder_input: these used to reach a cast that is undefined.
  EXPECT_FALSE(parse({"--out", "x", "--max-bytes", "1e120"}).has_value());
  EXPECT_FALSE(parse({"--out", "x", "--max-bytes", "inf"}).has_value());
  EXPECT_FALSE(parse({"--out", "x", "--device", "127.0.0.1:nan"}).has_value());
  EXPECT_FALSE(parse({"--out", "x", "--segment", "nan"}).has_value());
  EXPECT_FALSE(parse({"--out", "x", "--segment", "99999999999999999999"}).has_value());
  EXPECT_FALSE(parse({"--out", "x", "--segment", "86401"}).has_value());
  EXPECT_TRUE(parse({"--out", "x", "--segment", "86400"}).has_value());
}

TEST(RecorderOptions, AMissingValueOrAnUnknownOptionIsNamedOnce) {
  EXPECT_EQ(parse({"--out", "x", "--segment"}).error(), "--segment needs a value");
  EXPECT_EQ(parse({"--out", "x", "--nope"}).error(), "unknown option --nope");
}

TEST(RecorderOptions, APortIsAWholeNumberWhereverItIsGiven) {
  // 1984.5 read as 1984 once: a typo went to another port without a word.
  auto device = parse({"--out", "x", "--device", "127.0.0.1:1984.5"});
  ASSERT_FALSE(device.has_value());
  EXPECT_NE(device.error().find("1..65535"), std::string::npos) << device.error();
  EXPECT_FALSE(parse({"--out", "x", "--http", ":8080.5"}).has_value());
  EXPECT_FALSE(parse({"--out", "x", "--rtsp", "127.0.0.1:1e9"}).has_value());
  EXPECT_EQ(parse({"--out", "x", "--http", ":0"})->http->port, 0);  // any free port
}

TEST(RecorderOptions, ADeviceMaySteerAnotherVehicleThroughControl) {
  auto options = parse({"--out", "x", "--detect", "tag36h11", "--follow", "--device",
                        "10.0.0.2:1985,control=rcoip://10.0.0.3:9050", "--device", "10.0.0.4"});
  ASSERT_TRUE(options.has_value()) << options.error();
  EXPECT_EQ(options->devices[0].host, "10.0.0.2");
  EXPECT_EQ(options->devices[0].port, 1985);
  EXPECT_EQ(options->devices[0].control, (ControlTarget{"rcoip", "10.0.0.3", 9050}));
  EXPECT_FALSE(options->devices[1].control);
  EXPECT_EQ(parseControlTarget("btemp://robot")->port, 0);  // the protocol's default
  for (const char* bad : {"rcoip:/x", "tcp://x:1", "rcoip://", "rcoip://x:0", "rcoip://x:70000",
                          "btemp://x:1.5", "rcoip://a b:1"})
    EXPECT_FALSE(parseControlTarget(bad)) << bad;
  // Without follow, control= would steer nothing: said, not ignored.
  auto unfollowed = parse({"--out", "x", "--device", "10.0.0.2,control=rcoip://10.0.0.3"});
  ASSERT_FALSE(unfollowed.has_value());
  EXPECT_NE(unfollowed.error().find("follow"), std::string::npos) << unfollowed.error();
}

}  // namespace
}  // namespace wircam::recorder
