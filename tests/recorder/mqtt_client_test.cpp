// The recorder's MQTT client in this process, against a real mosquitto:
// what a recorder of many cameras meets (sockets numbered past select()'s
// 1024).
#include "fleet/mqtt_client.h"

#include <fcntl.h>
#include <gtest/gtest.h>

#include <mutex>
#include <vector>

#include "common/open_file_limit.h"
#include "common/socket.h"
#include "mqtt_broker.h"
#include "wait_for.h"

namespace {

using namespace wircam;
using namespace wircam::testing;
using namespace std::chrono_literals;

// Files held open until the next one the process opens is numbered
// `number` or more, as a hundred cameras' sockets and timers hold them.
std::vector<UniqueFd> holdFilesUpTo(int number) {
  std::vector<UniqueFd> held;
  for (;;) {
    UniqueFd file(open("/dev/null", O_RDONLY | O_CLOEXEC));
    if (!file.valid() || file.get() >= number) return held;
    held.push_back(std::move(file));
  }
}

TEST(RecorderMqttClient, SpeaksWithItsBrokerOverASocketNumberedPast1024) {
  constexpr int kPastSelect = 1100;
  if (raiseOpenFileLimit() < kPastSelect + 100)
    GTEST_SKIP() << "the hard limit of open files is under " << kPastSelect + 100;
  MosquittoBroker broker;
  ASSERT_TRUE(broker.running());
  MqttProbe probe(broker.port(), "wircam-test/#");
  ASSERT_TRUE(waitFor([&] {
    probe.publish("wircam-test/ready", "1");
    return !probe.messages("wircam-test/ready").empty();
  }));
  auto held = holdFilesUpTo(kPastSelect);
  ASSERT_GE(held.size(), static_cast<size_t>(kPastSelect - 64));

  std::mutex mutex;
  std::vector<std::string> received;
  recorder::MqttClient::Handlers handlers{
      .connected = [](recorder::MqttClient& client) { client.subscribe("wircam-test/in"); },
      .message =
          [&](const std::string&, const std::string& payload, bool) {
            std::lock_guard lock(mutex);
            received.push_back(payload);
          },
      .log = {}};
  auto url = recorder::parseMqttUrl(broker.url());
  ASSERT_TRUE(url) << url.error();
  auto client = recorder::MqttClient::start(*url, "past-select", {"wircam-test/will", "gone"},
                                            std::move(handlers));
  ASSERT_TRUE(client) << client.error();
  ASSERT_TRUE(waitFor([&] { return (*client)->connected(); }, 10s))
      << "never connected: mosquitto_loop()'s select() refuses such a socket";

  EXPECT_TRUE((*client)->publish("wircam-test/out", "hello"));
  EXPECT_TRUE(probe.waitFor(
      "wircam-test/out", [](auto& m) { return m.payload == "hello"; }, 5s));
  // Subscribed on connecting, which the broker confirms in its own time.
  EXPECT_TRUE(waitFor(
      [&] {
        probe.publish("wircam-test/in", "hi");
        std::lock_guard lock(mutex);
        return !received.empty();
      },
      5s));
  client->reset();  // a clean stop says the will itself
  EXPECT_TRUE(probe.waitFor(
      "wircam-test/will", [](auto& m) { return m.payload == "gone"; }, 5s));
}

}  // namespace
