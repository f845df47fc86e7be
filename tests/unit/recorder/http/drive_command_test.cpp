// The drive mode's messages: a command is taken only when every field is
// what it should be; anything else is refused (and the vehicle stops).
#include "http/drive_command.h"

#include <gtest/gtest.h>

namespace wircam::recorder {
namespace {

TEST(DriveCommand, TakesSeqSteeringAndThrottle) {
  auto command = parseDriveCommand(R"({"seq": 12, "steering": -0.5, "throttle": 1})");
  ASSERT_TRUE(command.has_value()) << command.error();
  EXPECT_EQ(command->seq, 12);
  EXPECT_DOUBLE_EQ(command->steering, -0.5);
  EXPECT_DOUBLE_EQ(command->throttle, 1.0);
  EXPECT_TRUE(parseDriveCommand(R"({"steering": 0, "throttle": 0})").has_value());
}

TEST(DriveCommand, RefusesAnythingElseAndSaysWhy) {
  struct Case {
    const char* text;
    const char* why;
  };
  for (const auto& c : {
           Case{"", "not a JSON object"},
           Case{"[1, 2]", "not a JSON object"},
           Case{"{\"steering\": 0", "not a JSON object"},
           Case{R"({"throttle": 0})", "no 'steering'"},
           Case{R"({"steering": "left", "throttle": 0})", "'steering' is not a number"},
           Case{R"({"steering": 0, "throttle": 1.5})", "'throttle' is outside -1..1"},
           Case{R"({"steering": 0, "throttle": 1e400})", "not a JSON object"},
           Case{R"({"seq": 1.5, "steering": 0, "throttle": 0})", "'seq' is not an integer"},
       }) {
    auto command = parseDriveCommand(c.text);
    ASSERT_FALSE(command.has_value()) << c.text;
    EXPECT_EQ(command.error(), c.why) << c.text;
  }
  std::string padded = R"({"steering": 0, "throttle": 0, "pad": ")" + std::string(300, 'x') + "\"}";
  EXPECT_EQ(parseDriveCommand(padded).error(), "longer than 256 bytes");
}

}  // namespace
}  // namespace wircam::recorder
