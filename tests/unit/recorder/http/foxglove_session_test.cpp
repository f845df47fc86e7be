#include "http/foxglove_session.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

namespace wircam::recorder {
namespace {

using namespace std::string_literals;
using nlohmann::json;

// A recorder with two cameras, "rover-cam0" (channels 1..5), which steers
// its vehicle, and "rover-cam1", which does not.
FoxgloveSession sessionOf(bool canDrive = true) {
  return FoxgloveSession(
      {.isChannel = [](uint32_t id) { return id >= 1 && id <= 5; },
       .isCamera = [](const std::string& name) { return name.starts_with("rover-cam"); },
       .isDrivable = [](const std::string& name) { return name == "rover-cam0"; },
       .canDrive = canDrive});
}

std::string publish(uint32_t channel, const std::string& payload) {
  std::string message = "\x01"s;
  for (int i = 0; i < 4; ++i) message.push_back(static_cast<char>(channel >> (8 * i) & 0xff));
  return message + payload;
}

const char* kAdvertiseDrive =
    R"({"op":"advertise","channels":[{"id":7,"topic":"/rover-cam0/drive","encoding":"json","schemaName":"wircam.Drive"}]})";

TEST(FoxgloveSession, SubscriptionsAreKeptByChannel) {
  auto session = sessionOf();
  auto outcome = session.text(
      R"({"op":"subscribe","subscriptions":[{"id":0,"channelId":1},{"id":1,"channelId":3}]})");
  EXPECT_TRUE(outcome.replies.empty());
  EXPECT_FALSE(outcome.close);
  EXPECT_EQ(session.subscriptionTo(1), 0u);
  EXPECT_EQ(session.subscriptionTo(3), 1u);
  EXPECT_FALSE(session.subscriptionTo(2));
  session.text(R"({"op":"unsubscribe","subscriptionIds":[0]})");
  EXPECT_FALSE(session.subscriptionTo(1));
  session.channelGone(3);
  EXPECT_FALSE(session.subscriptionTo(3));
}

TEST(FoxgloveSession, ASubscriptionThatCannotBeIsAnsweredWithAStatusNotAClose) {
  auto session = sessionOf();
  session.text(R"({"op":"subscribe","subscriptions":[{"id":0,"channelId":1}]})");
  auto outcome = session.text(
      R"({"op":"subscribe","subscriptions":[{"id":0,"channelId":2},{"id":1,"channelId":99},{"id":2,"channelId":1}]})");
  ASSERT_EQ(outcome.replies.size(), 3u);
  EXPECT_EQ(json::parse(outcome.replies[0])["message"], "subscription id 0 is in use");
  EXPECT_EQ(json::parse(outcome.replies[0])["level"], 2);
  EXPECT_EQ(json::parse(outcome.replies[1])["message"], "channel 99 is not advertised");
  EXPECT_EQ(json::parse(outcome.replies[2])["message"], "already subscribed to channel 1");
  EXPECT_FALSE(outcome.close);
  EXPECT_EQ(
      json::parse(
          session.text(R"({"op":"unsubscribe","subscriptionIds":[5]})").replies[0])["message"],
      "no subscription 5 to end");
}

TEST(FoxgloveSession, ADriveChannelDrivesItsCamera) {
  auto session = sessionOf();
  EXPECT_TRUE(session.text(kAdvertiseDrive).replies.empty());
  auto outcome = session.binary(publish(7, R"({"steering":-0.5,"throttle":1})"));
  ASSERT_EQ(outcome.drives.size(), 1u);
  EXPECT_EQ(outcome.drives[0].camera, "rover-cam0");
  EXPECT_EQ(outcome.drives[0].steering, -0.5);
  EXPECT_EQ(outcome.drives[0].throttle, 1);
  // As Foxglove's Teleop panel publishes: a Twist, angular.z positive to the left.
  outcome = session.binary(
      publish(7, R"({"linear":{"x":0.25,"y":0,"z":0},"angular":{"x":0,"y":0,"z":0.75}})"));
  ASSERT_EQ(outcome.drives.size(), 1u);
  EXPECT_EQ(outcome.drives[0].steering, 0.75);
  EXPECT_EQ(outcome.drives[0].throttle, 0.25);
  EXPECT_EQ(session.drivenCameras(), std::set<std::string>{"rover-cam0"});
}

TEST(FoxgloveSession, UnadvertisingTheDriveChannelSendsNeutral) {
  auto session = sessionOf();
  session.text(kAdvertiseDrive);
  session.binary(publish(7, R"({"steering":0,"throttle":1})"));
  auto outcome = session.text(R"({"op":"unadvertise","channelIds":[7]})");
  ASSERT_EQ(outcome.drives.size(), 1u);
  EXPECT_EQ(outcome.drives[0].throttle, 0);
  EXPECT_EQ(outcome.drives[0].steering, 0);
  EXPECT_TRUE(session.drivenCameras().empty());
}

TEST(FoxgloveSession, JunkClosesTheClientAndStopsWhatItDrove) {
  for (const std::string& junk :
       {publish(7, "{\"throttle\":"), publish(7, R"({"steering":0,"throttle":2})"),
        publish(7, R"({"linear":{"x":1},"angular":{"z":"left"}})"), publish(8, "{}"),
        "\x02\0\0\0\0"s, ""s}) {
    auto session = sessionOf();
    session.text(kAdvertiseDrive);
    session.binary(publish(7, R"({"steering":0,"throttle":1})"));
    auto outcome = session.binary(junk);
    ASSERT_TRUE(outcome.close) << junk;
    ASSERT_EQ(outcome.drives.size(), 1u) << junk;
    EXPECT_EQ(outcome.drives[0].throttle, 0);
  }
  auto session = sessionOf();
  session.text(kAdvertiseDrive);
  auto outcome = session.text(R"({"op":"fetchAsset","uri":"package://x","requestId":1})");
  EXPECT_EQ(outcome.close, "op 'fetchAsset' is not served here");
  // Advertised but never driven: neutral all the same, the client may have
  // meant to stop.
  ASSERT_EQ(outcome.drives.size(), 1u);
}

TEST(FoxgloveSession, OnlyACameraDriveChannelInJsonWithTheTokenIsTaken) {
  auto refusal = [](FoxgloveSession session, const char* advertise) {
    auto outcome = session.text(advertise);
    EXPECT_FALSE(outcome.close);
    return outcome.replies.empty() ? ""s
                                   : json::parse(outcome.replies[0])["message"].get<std::string>();
  };
  EXPECT_EQ(refusal(sessionOf(false), kAdvertiseDrive),
            "driving needs the recorder started with --http-token (given to this connection)");
  EXPECT_EQ(
      refusal(sessionOf(),
              R"({"op":"advertise","channels":[{"id":1,"topic":"/cmd_vel","encoding":"json"}]})"),
      "only /STREAM/drive is published here, STREAM a camera; not '/cmd_vel'");
  EXPECT_EQ(
      refusal(
          sessionOf(),
          R"({"op":"advertise","channels":[{"id":1,"topic":"/other-cam0/drive","encoding":"json"}]})"),
      "only /STREAM/drive is published here, STREAM a camera; not '/other-cam0/drive'");
  EXPECT_EQ(
      refusal(
          sessionOf(),
          R"({"op":"advertise","channels":[{"id":1,"topic":"/rover-cam0/drive","encoding":"ros1"}]})"),
      "/rover-cam0/drive takes JSON, not 'ros1'");
  // What is published on a refused channel goes nowhere, and the client
  // stays: it was told when it advertised.
  auto session = sessionOf(false);
  session.text(kAdvertiseDrive);
  auto outcome = session.binary(publish(7, R"({"steering":0,"throttle":1})"));
  EXPECT_FALSE(outcome.close);
  EXPECT_TRUE(outcome.drives.empty());
  EXPECT_TRUE(outcome.replies.empty());
}

}  // namespace
}  // namespace wircam::recorder
