// wirc-cli's JSON messages: what does not fit is refused, not wrapped.
#include "message_json.h"

#include <gtest/gtest.h>

namespace wircam::cli {
namespace {

TEST(MessageJson, ReadsAMessage) {
  auto message = fromJson(nlohmann::json::parse(R"({"type":"STST","camera":1,"port":5000})"));
  ASSERT_TRUE(message.has_value()) << message.error();
  EXPECT_EQ(std::get<wirc::Stst>(*message).port, 5000);
}

TEST(MessageJson, RefusesAValueTheFieldCannotHold) {
  auto message = fromJson(nlohmann::json::parse(R"({"type":"STST","camera":300,"port":5000})"));
  ASSERT_FALSE(message.has_value());
  EXPECT_EQ(message.error(), "\"camera\": 300 does not fit the field");
  EXPECT_FALSE(fromJson(nlohmann::json::parse(R"({"type":"EST","camera":-1})")).has_value());
}

TEST(MessageJson, RefusesFractions) {
  auto message = fromJson(nlohmann::json::parse(R"({"type":"EST","camera":90500.2})"));
  ASSERT_FALSE(message.has_value());
  EXPECT_EQ(message.error(), "numbers are whole numbers here");
}

}  // namespace
}  // namespace wircam::cli
