// The Foxglove server in this process, with libsoup's own WebSocket client:
// cameras come and go, and every client hears of it (advertise, unadvertise)
// without a recorder or a device.
#include "http/foxglove_server.h"

#include <gst/gst.h>
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <nlohmann/json.hpp>
#include <vector>

#include "common/h264_access_unit.h"
#include "gst_h264_start.h"
#include "main_loop_until.h"
#include "scene_cut_h264.h"
#include "websocket_test_client.h"

namespace wircam::recorder {
namespace {

using nlohmann::json;
using wircam::testing::runMainLoopUntil;
using namespace std::chrono_literals;

// A Foxglove client: libsoup's WebSocket client with the Foxglove
// subprotocol.
struct Client : wircam::testing::WebSocketTestClient {
  explicit Client(const std::string& url)
      : WebSocketTestClient(url, {.protocols = {kFoxgloveSubprotocol}}) {}
  // The op's messages so far.
  std::vector<json> said(const std::string& op) const {
    std::vector<json> found;
    for (const auto& text : texts) {
      auto message = json::parse(text, nullptr, false);
      if (message.is_object() && message.value("op", "") == op) found.push_back(message);
    }
    return found;
  }
};

TEST(FoxgloveServer, CamerasAddedAndRemovedAreAdvertisedAndUnadvertisedToEveryClient) {
  gst_init(nullptr, nullptr);
  FrameTap first, second;
  FoxgloveContent content;
  content.cameras = {{"rover-cam0", &first}};
  content.drive = [](const std::string&, double, double) { return std::optional<bool>(); };
  content.drivable = [](const std::string&) { return false; };
  auto server = FoxgloveServer::start({"", 0}, content, 10s);
  ASSERT_TRUE(server) << server.error();
  Client client((*server)->url());
  ASSERT_TRUE(runMainLoopUntil([&] { return !client.said("advertise").empty(); }));
  auto topics = [](const json& advertise) {
    std::vector<std::string> names;
    for (const auto& channel : advertise["channels"]) names.push_back(channel["topic"]);
    return names;
  };
  EXPECT_EQ(topics(client.said("advertise")[0]),
            (std::vector<std::string>{"/rover-cam0/image", "/rover-cam0/tags",
                                      "/rover-cam0/telemetry", "/rover-cam0/log"}));

  (*server)->addCamera({"rover-cam1", &second, nullptr, true});
  ASSERT_TRUE(runMainLoopUntil([&] { return client.said("advertise").size() == 2; }));
  auto added = client.said("advertise")[1];
  EXPECT_EQ(topics(added).back(), "/rover-cam1/pose");
  std::vector<uint32_t> ids;
  for (const auto& channel : added["channels"]) ids.push_back(channel["id"]);

  (*server)->removeCamera("rover-cam1");
  ASSERT_TRUE(runMainLoopUntil([&] { return !client.said("unadvertise").empty(); }));
  EXPECT_EQ(client.said("unadvertise")[0]["channelIds"].get<std::vector<uint32_t>>(), ids);
  // Back again: new channels, never the ids a client may still hold.
  (*server)->addCamera({"rover-cam1", &second});
  ASSERT_TRUE(runMainLoopUntil([&] { return client.said("advertise").size() == 3; }));
  for (const auto& channel : client.said("advertise")[2]["channels"])
    EXPECT_GT(channel["id"].get<uint32_t>(), ids.back());
  EXPECT_EQ((*server)->stats().clients, 1u);
}

// An encoder that makes non-IDR I-frames between IDRs (scene_cut_h264.h),
// its H.264 handed to the server as the recorder's is: a client that
// subscribes mid-stream gets an IDR with its SPS and PPS first, never an
// I-frame it cannot decode.
TEST(FoxgloveServer, AnH264SubscriberStartsOnAnIdrThoughIFramesComeBefore) {
  gst_init(nullptr, nullptr);
  FrameTap jpeg, encoded;
  GstElement* pipeline = testing::sceneCutH264Into(encoded);
  ASSERT_TRUE(pipeline);
  FoxgloveContent content;
  content.cameras = {{"rover-cam0", &jpeg, &encoded}};
  content.drive = [](const std::string&, double, double) { return std::optional<bool>(); };
  content.drivable = [](const std::string&) { return false; };
  auto server = FoxgloveServer::start({"", 0}, content, 10s);
  ASSERT_TRUE(server) << server.error();
  // Frames since the encoder's last IDR, counted as they pass.
  std::atomic<int> sinceIdr = -1;
  int counting = encoded.listen([&](GstSample* sample) {
    bool idr = gst::h264StartsDecoding(gst_sample_get_buffer(sample), gst_sample_get_caps(sample));
    sinceIdr = idr ? 0 : sinceIdr < 0 ? -1 : sinceIdr + 1;
  });
  gst_element_set_state(pipeline, GST_STATE_PLAYING);
  for (int round = 0; round < 3; ++round) {
    Client client((*server)->url());
    ASSERT_TRUE(runMainLoopUntil([&] { return !client.said("advertise").empty(); }));
    uint32_t image = client.said("advertise")[0]["channels"][0]["id"];
    // Between two IDRs, a different way each round.
    int after = 3 + 4 * round;
    ASSERT_TRUE(runMainLoopUntil([&] { return sinceIdr >= after && sinceIdr < after + 4; }, 3s))
        << sinceIdr << " frames since the last IDR, round " << round;
    json subscribe = {{"op", "subscribe"}, {"subscriptions", {{{"id", 1}, {"channelId", image}}}}};
    soup_websocket_connection_send_text(client.connection, subscribe.dump().c_str());
    ASSERT_TRUE(runMainLoopUntil([&] { return !client.binaries.empty(); }, 3s));
    const std::string& first = client.binaries[0];
    EXPECT_TRUE(startsDecoding(first, H264Framing::byteStream())) << "round " << round;
    EXPECT_NE(first.find(std::string("\0\0\1\x67", 4)), std::string::npos) << "no SPS";
  }
  gst_element_set_state(pipeline, GST_STATE_NULL);
  encoded.forget(counting);
  encoded.detach();
  gst_object_unref(pipeline);
}

}  // namespace
}  // namespace wircam::recorder
