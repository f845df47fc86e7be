// The Foxglove server in this process, with libsoup's own WebSocket client:
// cameras come and go, and every client hears of it (advertise, unadvertise)
// without a recorder or a device.
#include "http/foxglove_server.h"

#include <gst/gst.h>
#include <gtest/gtest.h>
#include <libsoup/soup.h>

#include <chrono>
#include <nlohmann/json.hpp>
#include <thread>
#include <vector>

namespace wircam::recorder {
namespace {

using nlohmann::json;
using namespace std::chrono_literals;

// Runs the default main context until `done`, at most 5 s.
template <typename Condition>
bool runUntil(Condition done) {
  auto until = std::chrono::steady_clock::now() + 5s;
  while (!done()) {
    if (std::chrono::steady_clock::now() > until) return false;
    if (!g_main_context_iteration(nullptr, FALSE)) std::this_thread::sleep_for(1ms);
  }
  return true;
}

struct Client {
  SoupSession* session = soup_session_new();
  SoupWebsocketConnection* connection = nullptr;
  std::vector<json> received;

  explicit Client(const std::string& url) {
    SoupMessage* message = soup_message_new("GET", url.c_str());
    const char* protocols[] = {kFoxgloveSubprotocol, nullptr};
    soup_session_websocket_connect_async(
        session, message, nullptr, const_cast<char**>(protocols), G_PRIORITY_DEFAULT, nullptr,
        [](GObject* source, GAsyncResult* result, gpointer self) {
          auto* client = static_cast<Client*>(self);
          client->connection =
              soup_session_websocket_connect_finish(SOUP_SESSION(source), result, nullptr);
          if (!client->connection) return;
          g_signal_connect(
              client->connection, "message",
              G_CALLBACK(+[](SoupWebsocketConnection*, gint type, GBytes* bytes, gpointer data) {
                if (type != SOUP_WEBSOCKET_DATA_TEXT) return;
                gsize size = 0;
                auto* text = static_cast<const char*>(g_bytes_get_data(bytes, &size));
                static_cast<Client*>(data)->received.push_back(
                    json::parse(std::string(text, size), nullptr, false));
              }),
              self);
        },
        this);
    g_object_unref(message);
  }
  ~Client() {
    if (connection) {
      g_signal_handlers_disconnect_matched(connection, G_SIGNAL_MATCH_DATA, 0, 0, nullptr, nullptr,
                                           this);
      g_object_unref(connection);
    }
    g_object_unref(session);
  }
  // The op's messages so far.
  std::vector<json> said(const std::string& op) const {
    std::vector<json> found;
    for (const auto& message : received)
      if (message.is_object() && message.value("op", "") == op) found.push_back(message);
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
  ASSERT_TRUE(runUntil([&] { return !client.said("advertise").empty(); }));
  auto topics = [](const json& advertise) {
    std::vector<std::string> names;
    for (const auto& channel : advertise["channels"]) names.push_back(channel["topic"]);
    return names;
  };
  EXPECT_EQ(topics(client.said("advertise")[0]),
            (std::vector<std::string>{"/rover-cam0/image", "/rover-cam0/tags",
                                      "/rover-cam0/telemetry", "/rover-cam0/log"}));

  (*server)->addCamera({"rover-cam1", &second, nullptr, true});
  ASSERT_TRUE(runUntil([&] { return client.said("advertise").size() == 2; }));
  auto added = client.said("advertise")[1];
  EXPECT_EQ(topics(added).back(), "/rover-cam1/pose");
  std::vector<uint32_t> ids;
  for (const auto& channel : added["channels"]) ids.push_back(channel["id"]);

  (*server)->removeCamera("rover-cam1");
  ASSERT_TRUE(runUntil([&] { return !client.said("unadvertise").empty(); }));
  EXPECT_EQ(client.said("unadvertise")[0]["channelIds"].get<std::vector<uint32_t>>(), ids);
  // Back again: new channels, never the ids a client may still hold.
  (*server)->addCamera({"rover-cam1", &second});
  ASSERT_TRUE(runUntil([&] { return client.said("advertise").size() == 3; }));
  for (const auto& channel : client.said("advertise")[2]["channels"])
    EXPECT_GT(channel["id"].get<uint32_t>(), ids.back());
  EXPECT_EQ((*server)->stats().clients, 1u);
}

}  // namespace
}  // namespace wircam::recorder
