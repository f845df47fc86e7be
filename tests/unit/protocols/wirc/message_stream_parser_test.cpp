#include "wirc/message_stream_parser.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

namespace wircam::wirc {
namespace {

struct Collected {
  std::vector<Message> messages;
  std::vector<ProtocolError> errors;
};

class MessageStreamParserTest : public ::testing::Test {
 protected:
  void feed(const Bytes& bytes) {
    parser_.feed(bytes, [this](const Expected<Message, ProtocolError>& result) {
      if (result)
        got_.messages.push_back(*result);
      else
        got_.errors.push_back(result.error());
    });
  }

  MessageStreamParser parser_;
  Collected got_;
};

Bytes wire(const Message& message) { return *encode(message); }

Bytes concat(std::initializer_list<Bytes> parts) {
  Bytes all;
  for (const auto& part : parts) all.insert(all.end(), part.begin(), part.end());
  return all;
}

const Message kWst = Wst{.connectionId = 1, .cameraCount = 2, .controlPort = 4000};
const Message kAgr = Agr{
    .connectionId = 1, .priority = 3, .name = "me", .notification = AccessNotification::Granted};
const Message kPsd = Psd{.batteryMillivolts = 7200, .analogMillivolts = 0, .inputs = {}};

TEST_F(MessageStreamParserTest, SplitsSeveralMessagesInOneRead) {
  feed(concat({wire(kWst), wire(kAgr), wire(kPsd)}));
  ASSERT_EQ(got_.messages.size(), 3u);
  EXPECT_EQ(got_.messages[0], kWst);
  EXPECT_EQ(got_.messages[1], kAgr);
  EXPECT_EQ(got_.messages[2], kPsd);
  EXPECT_TRUE(got_.errors.empty());
}

TEST_F(MessageStreamParserTest, JoinsAMessageSplitAcrossReadsAtEveryPoint) {
  Bytes bytes = concat({wire(kAgr), wire(kWst)});
  for (size_t cut = 0; cut <= bytes.size(); ++cut) {
    MessageStreamParser parser;
    std::vector<Message> messages;
    auto handler = [&](const Expected<Message, ProtocolError>& r) {
      ASSERT_TRUE(r.has_value());
      messages.push_back(*r);
    };
    parser.feed(std::span(bytes).first(cut), handler);
    parser.feed(std::span(bytes).subspan(cut), handler);
    ASSERT_EQ(messages.size(), 2u) << cut;
    EXPECT_EQ(messages[0], kAgr);
    EXPECT_EQ(parser.pendingBytes(), 0u);
  }
}

TEST_F(MessageStreamParserTest, AcceptsOneByteAtATime) {
  Bytes bytes = concat({wire(kWst), wire(kPsd)});
  for (uint8_t b : bytes) feed(Bytes{b});
  EXPECT_EQ(got_.messages.size(), 2u);
}

TEST_F(MessageStreamParserTest, SkipsGarbageBetweenMessages) {
  feed(concat({Bytes{0x00, 0x13, 0xAA, 0x00, 0xBB}, wire(kWst), Bytes{0xAA, 0xAA}, wire(kPsd)}));
  ASSERT_EQ(got_.messages.size(), 2u);
  EXPECT_TRUE(got_.errors.empty());
  EXPECT_EQ(parser_.stats().garbageBytes, 7u);
}

TEST_F(MessageStreamParserTest, ResyncsOnTheNextSyncAfterABadCrc) {
  Bytes bad = wire(kAgr);
  bad.back() ^= 0xFF;
  feed(concat({bad, wire(kWst)}));
  ASSERT_EQ(got_.messages.size(), 1u);
  EXPECT_EQ(got_.messages[0], kWst);
  ASSERT_EQ(got_.errors.size(), 1u);
  EXPECT_EQ(got_.errors[0].kind, ErrorKind::BadCrc);
  EXPECT_EQ(parser_.stats().badCrc, 1u);
}

TEST_F(MessageStreamParserTest, FindsARealMessageSwallowedByAFalseSync) {
  // AA BB with a large LEN claims the next bytes; the CRC fails and the
  // parser must find the real frame inside what it had buffered.
  Bytes falseStart = {0xAA, 0xBB, 0x21, 0x30};
  Bytes bytes = concat({falseStart, wire(kWst), Bytes(60, 0x00), wire(kPsd)});
  feed(bytes);
  ASSERT_EQ(got_.messages.size(), 2u);
  EXPECT_EQ(got_.messages[0], kWst);
  EXPECT_EQ(got_.messages[1], kPsd);
}

TEST_F(MessageStreamParserTest, ReportsAndSkipsAnUnknownCommand) {
  Bytes body = {1, 2, 3};
  feed(concat({frameRaw(0x77, body), wire(kWst)}));
  ASSERT_EQ(got_.errors.size(), 1u);
  EXPECT_EQ(got_.errors[0].kind, ErrorKind::UnknownCommand);
  EXPECT_EQ(got_.errors[0].command, 0x77);
  ASSERT_EQ(got_.messages.size(), 1u);
  EXPECT_EQ(parser_.stats().unknownCommands, 1u);
}

TEST_F(MessageStreamParserTest, ReportsAnInvalidFieldWithItsCommand) {
  Bytes body(24, 0);  // PCD of zeros: valid frame, invalid values
  feed(concat({frameRaw(0x21, body), wire(kWst)}));
  ASSERT_EQ(got_.errors.size(), 1u);
  EXPECT_EQ(got_.errors[0].kind, ErrorKind::InvalidField);
  EXPECT_EQ(got_.errors[0].command, 0x21);
  EXPECT_EQ(got_.messages.size(), 1u);
}

TEST_F(MessageStreamParserTest, KeepsAtMostOneFrameWhateverItIsFed) {
  std::mt19937 random(42);
  Bytes noise(1 << 16);
  for (auto& b : noise) b = static_cast<uint8_t>(random());
  for (size_t i = 0; i < noise.size(); i += 1000) {
    feed(Bytes(noise.begin() + i, noise.begin() + std::min(noise.size(), i + 1000)));
    EXPECT_LE(parser_.pendingBytes(), kMaxFrameSize);
  }
  feed(Bytes(300, 0));  // flush whatever partial frame the noise left
  feed(wire(kWst));
  ASSERT_FALSE(got_.messages.empty());
  EXPECT_EQ(got_.messages.back(), kWst);
}

}  // namespace
}  // namespace wircam::wirc
