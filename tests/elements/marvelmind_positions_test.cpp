// marvelmindpositions in real pipelines, against the simulated dashboard.
#include <gst/app/gstappsink.h>
#include <gtest/gtest.h>

#include <array>
#include <thread>

#include "marvelmind_dashboard.h"
#include "pipelines.h"
#include "wirc_position_meta.h"

namespace wircam {
namespace {

using namespace std::chrono_literals;

std::unique_ptr<sim::MarvelmindDashboard> dashboardAt(std::array<double, 3> where,
                                                      sim::DashboardConfig config = {}) {
  config.noise = 0;
  config.rate = 32;
  auto dashboard =
      sim::MarvelmindDashboard::start(std::move(config), [where](size_t) { return where; });
  EXPECT_TRUE(dashboard);
  return dashboard ? std::move(*dashboard) : nullptr;
}

std::string pipelineFor(const std::string& positions) {
  return "videotestsrc is-live=true ! video/x-raw,framerate=30/1,width=64,height=48 ! "
         "marvelmindpositions name=positions " +
         positions + " ! appsink name=sink max-buffers=100 drop=true sync=false";
}

// The element messages of `name` posted within `timeout` (0: those queued).
std::vector<GstStructure*> messagesNamed(GstElement* pipeline, const char* name, size_t want,
                                         std::chrono::milliseconds timeout) {
  GstBus* bus = gst_element_get_bus(pipeline);
  std::vector<GstStructure*> found;
  auto end = std::chrono::steady_clock::now() + timeout;
  while (found.size() < want) {
    // With time left, wait for the next; past it, take only what is queued.
    bool waiting = std::chrono::steady_clock::now() < end;
    GstMessage* message =
        gst_bus_timed_pop_filtered(bus, waiting ? 50 * GST_MSECOND : 0, GST_MESSAGE_ELEMENT);
    if (!message && !waiting) break;
    if (!message) continue;
    if (gst_message_has_name(message, name))
      found.push_back(gst_structure_copy(gst_message_get_structure(message)));
    gst_message_unref(message);
  }
  gst_object_unref(bus);
  return found;
}

TEST(MarvelmindPositions, JoinsTheNearestPositionToEachFrameAndPostsEachNewOne) {
  auto dashboard = dashboardAt({2.5, -1.25, 0.3});
  ASSERT_TRUE(dashboard);
  GstElement* pipeline = testing::launch(pipelineFor("port=" + std::to_string(dashboard->port()) +
                                                     " beacons=5 poll-rate=20 units=mm"));
  ASSERT_TRUE(pipeline);
  gst_element_set_state(pipeline, GST_STATE_PLAYING);
  // Positions measured before PLAYING have no running time; a slow start
  // (a sanitizer's) may queue all five of them, so count from PLAYING on.
  ASSERT_EQ(gst_element_get_state(pipeline, nullptr, nullptr, 5 * GST_SECOND),
            GST_STATE_CHANGE_SUCCESS);
  for (auto* early : messagesNamed(pipeline, "marvelmind-position", SIZE_MAX, 0ms))
    gst_structure_free(early);
  auto messages = messagesNamed(pipeline, "marvelmind-position", 5, 3s);
  ASSERT_EQ(messages.size(), 5u);
  for (auto* s : messages) {
    guint beacon = 0;
    double x = 0;
    guint64 runningTime = 0;
    EXPECT_TRUE(gst_structure_get_uint(s, "beacon", &beacon));
    EXPECT_TRUE(gst_structure_get_double(s, "x", &x));
    EXPECT_TRUE(gst_structure_get_uint64(s, "running-time", &runningTime));
    EXPECT_EQ(beacon, 5u);
    EXPECT_DOUBLE_EQ(x, 2.5);
    // (The first may have been measured just before PLAYING.)
    if (s == messages.back()) {
      EXPECT_NE(runningTime, GST_CLOCK_TIME_NONE);
    }
    gst_structure_free(s);
  }
  // Frames after the first positions carry one meta each (those queued in
  // the appsink from before are skipped).
  GstElement* sink = gst_bin_get_by_name(GST_BIN(pipeline), "sink");
  while (GstSample* queued = gst_app_sink_try_pull_sample(GST_APP_SINK(sink), 0))
    gst_sample_unref(queued);
  int withMeta = 0;
  for (int i = 0; i < 15; ++i) {
    GstSample* sample = gst_app_sink_try_pull_sample(GST_APP_SINK(sink), GST_SECOND);
    ASSERT_TRUE(sample);
    GstBuffer* buffer = gst_sample_get_buffer(sample);
    if (auto* meta = gst_buffer_get_wirc_position_meta(buffer)) {
      ++withMeta;
      EXPECT_EQ(meta->beacon, 5u);
      EXPECT_DOUBLE_EQ(meta->y, -1.25);
      EXPECT_DOUBLE_EQ(meta->z, 0.3);
      // Polled at 20 Hz: the nearest measurement is within a poll period
      // (and a frame) of the frame.
      EXPECT_LT(std::abs(meta->offset), static_cast<gint64>(50 + 34 + 20) * GST_MSECOND)
          << meta->offset;
    }
    gst_sample_unref(sample);
  }
  EXPECT_GE(withMeta, 14);
  GstStructure* stats = nullptr;
  GstElement* positionsElement = gst_bin_get_by_name(GST_BIN(pipeline), "positions");
  g_object_get(positionsElement, "stats", &stats, nullptr);
  gst_object_unref(positionsElement);
  guint64 positions = 0, rejected = 1;
  gst_structure_get_uint64(stats, "positions", &positions);
  gst_structure_get_uint64(stats, "rejected", &rejected);
  EXPECT_GE(positions, 5u);
  EXPECT_EQ(rejected, 0u);
  gst_structure_free(stats);
  gst_object_unref(sink);
  gst_element_set_state(pipeline, GST_STATE_NULL);
  gst_object_unref(pipeline);
}

TEST(MarvelmindPositions, PostsStaleWhenTheDashboardStopsAndJoinsNothingAfter) {
  auto dashboard = dashboardAt({1, 1, 1});
  ASSERT_TRUE(dashboard);
  GstElement* pipeline = testing::launch(
      pipelineFor("port=" + std::to_string(dashboard->port()) + " beacons=5 stale-timeout=300"));
  gst_element_set_state(pipeline, GST_STATE_PLAYING);
  ASSERT_EQ(messagesNamed(pipeline, "marvelmind-position", 2, 3s).size(), 2u);
  dashboard.reset();
  auto stale = messagesNamed(pipeline, "marvelmind-stale", 1, 2s);
  ASSERT_EQ(stale.size(), 1u);
  EXPECT_NE(std::string(gst_structure_get_string(stale[0], "reason")).find("no reply"),
            std::string::npos);
  gst_structure_free(stale[0]);
  // Frames from now on are not joined to the old position.
  // What queued before goes, and so does the one frame the streaming
  // thread may have been carrying when the position went stale.
  GstElement* sink = gst_bin_get_by_name(GST_BIN(pipeline), "sink");
  while (GstSample* queued = gst_app_sink_try_pull_sample(GST_APP_SINK(sink), 0))
    gst_sample_unref(queued);
  if (GstSample* carried = gst_app_sink_try_pull_sample(GST_APP_SINK(sink), GST_SECOND))
    gst_sample_unref(carried);
  for (int i = 0; i < 5; ++i) {
    GstSample* sample = gst_app_sink_try_pull_sample(GST_APP_SINK(sink), GST_SECOND);
    ASSERT_TRUE(sample);
    EXPECT_EQ(gst_buffer_get_wirc_position_meta(gst_sample_get_buffer(sample)), nullptr);
    gst_sample_unref(sample);
  }
  gst_object_unref(sink);
  gst_element_set_state(pipeline, GST_STATE_NULL);
  gst_object_unref(pipeline);
}

TEST(MarvelmindPositions, TakesPushedPositionsInStreamMode) {
  // A free port for the element to listen on, where the dashboard pushes.
  auto probe = bindUdp(SocketAddress::loopback(0));
  ASSERT_TRUE(probe);
  uint16_t port = localAddress(probe->get()).port();
  probe->reset();
  GstElement* pipeline = testing::launch(
      pipelineFor("mode=stream listen-port=" + std::to_string(port) + " beacons=7"));
  gst_element_set_state(pipeline, GST_STATE_PLAYING);
  auto dashboard =
      dashboardAt({0.5, 0.5, 0.5}, {.beacons = {7}, .pushTo = SocketAddress::loopback(port)});
  ASSERT_TRUE(dashboard);
  EXPECT_EQ(messagesNamed(pipeline, "marvelmind-position", 3, 3s).size(), 3u);
  gst_element_set_state(pipeline, GST_STATE_NULL);
  gst_object_unref(pipeline);
}

TEST(MarvelmindPositions, RefusesToStartWithoutADashboardAddress) {
  EXPECT_NE(testing::firstErrorOf(pipelineFor("host=no.such.host.invalid"), 3s), "");
}

}  // namespace
}  // namespace wircam
