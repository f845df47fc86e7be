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

TEST(MessageJson, RefusesAMisspeltFieldAndAMissingOneInsteadOfADefault) {
  auto misspelt = fromJson(nlohmann::json::parse(R"({"type":"STST","camra":1,"port":5000})"));
  ASSERT_FALSE(misspelt.has_value());
  EXPECT_EQ(misspelt.error(), "\"camra\" is no field of STST (STST's fields: camera, port)");
  auto missing = fromJson(nlohmann::json::parse(R"({"type":"STST","camera":1})"));
  ASSERT_FALSE(missing.has_value());
  EXPECT_EQ(missing.error(), "STST needs \"port\" (STST's fields: camera, port)");
  // A message without fields takes none.
  EXPECT_TRUE(fromJson(nlohmann::json::parse(R"({"type":"TLR"})")).has_value());
  EXPECT_FALSE(fromJson(nlohmann::json::parse(R"({"type":"TLR","x":1})")).has_value());
  // WCFG takes its password, and what decode writes (passwordLength) is not input.
  auto wifi = fromJson(nlohmann::json::parse(
      R"({"type":"WCFG","ssid":"car","password":"secret12","accessPoint":true,)"
      R"("secured":true,"channel":6,"country":"HU"})"));
  ASSERT_TRUE(wifi.has_value()) << wifi.error();
  EXPECT_EQ(std::get<wirc::Wcfg>(*wifi).password, "secret12");
}

TEST(MessageJson, RefusesFractions) {
  auto message = fromJson(nlohmann::json::parse(R"({"type":"EST","camera":90500.2})"));
  ASSERT_FALSE(message.has_value());
  EXPECT_EQ(message.error(), "numbers are whole numbers here");
}

}  // namespace
}  // namespace wircam::cli
