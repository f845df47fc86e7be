// The drive mode's messages: a command is taken only when every field is
// what it should be; anything else is refused (and the vehicle stops).
#include "fleet/drive_command.h"

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

// Whatever carries them (WebSocket or data channel), messages are obeyed,
// refused with neutral, or told the vehicle cannot be driven.
TEST(DriveCommand, AMessageIsObeyedOrRefusedWithNeutral) {
  std::vector<std::pair<double, double>> sent;
  std::optional<bool> obeys = true;
  DriveFunction drive = [&](double steering, double throttle) {
    sent.emplace_back(steering, throttle);
    return obeys;
  };
  EXPECT_EQ(obeyDriveMessage(R"({"seq": 7, "steering": 0.5, "throttle": -1})", drive),
            R"({"ack":7,"obeyed":true})");
  EXPECT_EQ(sent.back(), std::make_pair(0.5, -1.0));
  EXPECT_EQ(obeyDriveMessage("junk", drive), R"({"error":"not a JSON object","neutral":true})");
  EXPECT_EQ(sent.back(), std::make_pair(0.0, 0.0));
  sent.clear();
  EXPECT_EQ(obeyDriveMessage(std::nullopt, drive),
            R"({"error":"not a text message","neutral":true})");
  EXPECT_EQ(sent, (std::vector<std::pair<double, double>>{{0.0, 0.0}}));
  obeys = std::nullopt;
  EXPECT_EQ(obeyDriveMessage(R"({"steering": 0, "throttle": 0})", drive),
            R"({"error":"this camera's vehicle cannot be driven"})");
}

}  // namespace
}  // namespace wircam::recorder
