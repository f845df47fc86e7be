#include "foxglove/foxglove_protocol.h"

#include <glib.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "foxglove/foxglove_messages.h"

namespace wircam::recorder {
namespace {

using namespace std::string_literals;
using nlohmann::json;

TEST(FoxgloveProtocol, AProtobufChannelIsAdvertisedWithItsDescriptorsInBase64) {
  auto channels = foxgloveChannels({.positions = true});
  ASSERT_EQ(channels.size(), 5u);
  auto message = json::parse(
      advertiseMessage({{7, foxgloveTopicName("rover-cam0", channels[0]), &channels[0]},
                        {8, foxgloveTopicName("rover-cam0", channels[2]), &channels[2]}}));
  EXPECT_EQ(message["op"], "advertise");
  const auto& image = message["channels"][0];
  EXPECT_EQ(image["id"], 7);
  EXPECT_EQ(image["topic"], "/rover-cam0/image");
  EXPECT_EQ(image["encoding"], "protobuf");
  EXPECT_EQ(image["schemaName"], "foxglove.CompressedImage");
  EXPECT_EQ(image["schemaEncoding"], "protobuf");
  gsize size = 0;
  guchar* decoded = g_base64_decode(image["schema"].get<std::string>().c_str(), &size);
  EXPECT_EQ(std::string(reinterpret_cast<char*>(decoded), size), foxgloveDescriptorSet());
  g_free(decoded);
  const auto& telemetry = message["channels"][1];
  EXPECT_EQ(telemetry["encoding"], "json");
  EXPECT_EQ(telemetry["schemaEncoding"], "jsonschema");
  EXPECT_EQ(json::parse(telemetry["schema"].get<std::string>())["title"], "wircam.Telemetry");
  EXPECT_EQ(channels[4].schemaName, "foxglove.PoseInFrame");
  EXPECT_EQ(foxgloveChannels({}).size(), 4u);
  EXPECT_EQ(foxgloveChannels({.video = true})[0].schemaName, "foxglove.CompressedVideo");
}

TEST(FoxgloveProtocol, MessageDataIsLittleEndianAndItsSubscriptionCanBeRewritten) {
  std::string frame = messageDataHead(0x01020304, 0x1122334455667788) + "body";
  EXPECT_EQ(frame.substr(0, kMessageDataHeadSize),
            "\x01\x04\x03\x02\x01\x88\x77\x66\x55\x44\x33\x22\x11"s);
  setSubscriptionId(frame, 9);
  EXPECT_EQ(frame.substr(1, 4), "\x09\0\0\0"s);
  EXPECT_EQ(frame.substr(kMessageDataHeadSize), "body");
}

TEST(FoxgloveProtocol, ClientOpsAreReadWithTheirFields) {
  auto subscribe = parseClientText(
      R"({"op":"subscribe","subscriptions":[{"id":0,"channelId":3},{"id":1,"channelId":4}]})");
  ASSERT_TRUE(subscribe);
  auto& subscriptions = std::get<ClientSubscribe>(*subscribe).subscriptions;
  ASSERT_EQ(subscriptions.size(), 2u);
  EXPECT_EQ(subscriptions[1], std::pair(1u, 4u));
  auto advertise = parseClientText(
      R"({"op":"advertise","channels":[{"id":2,"topic":"/a/drive","encoding":"json"}]})");
  ASSERT_TRUE(advertise);
  EXPECT_EQ(std::get<ClientAdvertise>(*advertise).channels[0].topic, "/a/drive");
  EXPECT_TRUE(parseClientText(R"({"op":"unsubscribe","subscriptionIds":[0]})"));
  EXPECT_TRUE(parseClientText(R"({"op":"unadvertise","channelIds":[2]})"));
}

TEST(FoxgloveProtocol, WhatIsNotAServedOpIsRefusedWithTheReason) {
  EXPECT_EQ(parseClientText("not json").error(), "not a JSON object");
  EXPECT_EQ(parseClientText("[1]").error(), "not a JSON object");
  EXPECT_EQ(parseClientText(R"({"subscriptions":[]})").error(), "'op' is not a string");
  EXPECT_EQ(parseClientText(R"({"op":"getParameters","parameterNames":[]})").error(),
            "op 'getParameters' is not served here");
  EXPECT_EQ(
      parseClientText(R"({"op":"subscribe","subscriptions":[{"id":-1,"channelId":1}]})").error(),
      "'id' is not an unsigned 32-bit integer");
  EXPECT_EQ(
      parseClientText(R"({"op":"subscribe","subscriptions":[{"id":4294967296,"channelId":1}]})")
          .error(),
      "'id' is not an unsigned 32-bit integer");
  EXPECT_EQ(parseClientText(R"({"op":"unsubscribe","subscriptionIds":["a"]})").error(),
            "'subscriptionIds' holds something other than ids");
  EXPECT_EQ(
      parseClientText(R"({"op":"advertise","channels":[{"id":1,"topic":"/a/drive"}]})").error(),
      "'encoding' is not a string");
}

TEST(FoxgloveProtocol, BinaryClientMessagesCarryTheirChannel) {
  auto data = parseClientBinary("\x01\x05\0\0\0{}"s);
  ASSERT_TRUE(data);
  EXPECT_EQ(data->channelId, 5u);
  EXPECT_EQ(data->payload, "{}");
  EXPECT_EQ(parseClientBinary("").error(), "an empty binary message");
  EXPECT_EQ(parseClientBinary("\x02\0\0\0\0"s).error(), "binary opcode 2 is not served here");
  EXPECT_EQ(parseClientBinary("\x01\x05\0"s).error(), "a message data shorter than its channel id");
}

}  // namespace
}  // namespace wircam::recorder
