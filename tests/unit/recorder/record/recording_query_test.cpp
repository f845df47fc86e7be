// Which recordings ?camera=&vehicle=&day= picks from the index's entries.
#include "record/recording_query.h"

#include <gtest/gtest.h>

namespace {

using namespace wircam::recorder;
using Json = nlohmann::json;

Json entry(const std::string& camera, const std::string& start, double seconds,
           Json vehicle = nullptr) {
  return {{"camera", camera}, {"start_utc", start}, {"duration_s", seconds}, {"vehicle", vehicle}};
}

TEST(RecordingQuery, PicksByCameraVehicleSerialOrNameAndUtcDayByOverlap) {
  auto q = [](const char* camera, const char* vehicle, const char* day) {
    auto query = recordingQueryOf(camera, vehicle, day);
    EXPECT_TRUE(query) << query.error();
    return *query;
  };
  Json car7 = {{"name", "car-7"}, {"serial", "S7"}};
  auto late = entry("rover-cam0", "2026-11-24T23:59:30.000Z", 60, car7);  // across midnight
  auto morning = entry("other-cam0", "2026-11-25T08:00:00.000Z", 60);
  EXPECT_TRUE(q(nullptr, nullptr, nullptr).any());
  EXPECT_TRUE(matches(q(nullptr, nullptr, nullptr), morning));
  EXPECT_TRUE(matches(q("rover-cam0", nullptr, nullptr), late));
  EXPECT_FALSE(matches(q("rover-cam0", nullptr, nullptr), morning));
  EXPECT_TRUE(matches(q(nullptr, "S7", nullptr), late));
  EXPECT_TRUE(matches(q(nullptr, "car-7", nullptr), late));
  EXPECT_FALSE(matches(q(nullptr, "car", nullptr), late));
  EXPECT_FALSE(matches(q(nullptr, "S7", nullptr), morning));  // its vehicle unknown
  EXPECT_TRUE(matches(q(nullptr, nullptr, "2026-11-24"), late));
  EXPECT_TRUE(matches(q(nullptr, nullptr, "2026-11-25"), late));
  EXPECT_FALSE(matches(q(nullptr, nullptr, "2026-11-24"), morning));
  EXPECT_FALSE(matches(q(nullptr, nullptr, "2026-11-26"), morning));
  EXPECT_FALSE(matches(q(nullptr, nullptr, "2026-11-25"), entry("c", "not a time", 1)));
}

TEST(RecordingQuery, RefusesADayThatIsNotADateAndSaysItselfBackEscaped) {
  for (const char* day : {"2026-13-01", "2026-11-31", "yesterday", "2026-11-25T00:00", "2026-1-5x"})
    EXPECT_FALSE(recordingQueryOf(nullptr, nullptr, day)) << day;
  auto query = recordingQueryOf("a b&c", "S7", "2026-11-25");
  ASSERT_TRUE(query);
  EXPECT_EQ(queryString(*query), "?camera=a%20b%26c&vehicle=S7&day=2026-11-25");
  EXPECT_EQ(queryString(*recordingQueryOf(nullptr, "", "")), "");
}

}  // namespace
