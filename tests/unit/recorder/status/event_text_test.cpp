#include "status/event_text.h"

#include <gtest/gtest.h>

namespace wircam::recorder {
namespace {

TEST(EventText, EachEventReadsAsOneLine) {
  EXPECT_EQ(eventText({{"type", "session"}, {"event", "link lost: no frame for 2 s"}}),
            "link lost: no frame for 2 s");
  EXPECT_EQ(eventText({{"type", "vehicle"}, {"event", "login ok"}, {"state", "live"}}),
            "vehicle: login ok");
  EXPECT_EQ(eventText({{"type", "state"}, {"state", "no-video"}}), "state: no-video");
  EXPECT_EQ(eventText({{"type", "segment-closed"}, {"file", "a.mkv"}, {"frames", 150}}),
            "segment closed: a.mkv (150 frames)");
  EXPECT_EQ(eventText({{"type", "position-stale"}, {"beacon", 5}, {"reason", "silent"}}),
            "position-stale {\"beacon\":5,\"reason\":\"silent\"}");
  EXPECT_EQ(eventText({{"type", "hook-failed"}}), "hook-failed");
}

}  // namespace
}  // namespace wircam::recorder
