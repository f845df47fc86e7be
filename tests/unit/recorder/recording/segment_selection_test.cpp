// The times an export takes (--start, --end, /api/export): ISO 8601 as
// people write it, and nothing a calendar does not have.
#include "recording/segment_selection.h"

#include <gtest/gtest.h>

namespace wircam::recorder {
namespace {

constexpr int64_t kSecond = 1000000000;

TEST(ExportTime, TakesUtcOffsetsAndAnyNumberOfFractionDigits) {
  auto utc = parseIsoTime("2026-11-27T16:21:30Z");
  ASSERT_TRUE(utc);
  EXPECT_EQ(*utc, 1795796490 * kSecond);
  EXPECT_EQ(parseIsoTime("2026-11-27T17:21:30+01:00"), utc);
  EXPECT_EQ(parseIsoTime("2026-11-27T16:21:30.5Z"), *utc + kSecond / 2);
  // ISO 8601 sets no limit on the digits: past nanoseconds they are cut
  // (twelve were refused as "not an ISO 8601 time", a stranger's trial).
  EXPECT_EQ(parseIsoTime("2026-11-27T16:21:30.123456789012Z"), *utc + 123456789);
}

TEST(ExportTime, RefusesDaysTheMonthHasNot) {
  // February 30 was taken as March 2.
  EXPECT_FALSE(parseIsoTime("2026-02-30T16:21:30Z"));
  EXPECT_FALSE(parseIsoTime("2026-02-29T00:00:00Z"));  // 2026 is no leap year
  EXPECT_TRUE(parseIsoTime("2028-02-29T00:00:00Z"));
  EXPECT_FALSE(parseIsoTime("1900-02-29T00:00:00Z"));
  EXPECT_TRUE(parseIsoTime("2000-02-29T00:00:00Z"));
  EXPECT_FALSE(parseIsoTime("2026-04-31T00:00:00Z"));
  EXPECT_TRUE(parseIsoTime("2026-12-31T23:59:59Z"));
  for (const char* bad : {"2026-13-01T00:00:00Z", "2026-11-27", "2026-11-27T16:21:30.Z",
                          "2026-11-27T16:21:30+1:00", "yesterday"})
    EXPECT_FALSE(parseIsoTime(bad)) << bad;
}

}  // namespace
}  // namespace wircam::recorder
