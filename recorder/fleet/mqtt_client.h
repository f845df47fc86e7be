// An MQTT client on a thread of its own (libmosquitto, opened on the first
// start), for the recorder's fleet topics. Publishing never waits: it hands
// the message to the library, or drops and counts it while the broker is
// away or too much is still unsent. The connection is made again with backoff (1 s doubling to
// 30 s) for as long as the client lives, and every wait is bounded, so a
// dead broker never holds up a recording or its stop.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "common/expected.h"
#include "fleet/mqtt_url.h"

struct mosquitto;
struct mosquitto_message;

namespace wircam::recorder {
struct MosquittoLibrary;
}

namespace wircam::recorder {

// Without a topic, none (a client that only listens).
struct MqttWill {
  std::string topic;
  std::string payload;
};

class MqttClient {
 public:
  struct Handlers {
    // Each runs on the client's thread and must not block.
    // Subscribe and publish what a new session needs (the client is passed:
    // this may run before start() has returned).
    std::function<void(MqttClient&)> connected;
    std::function<void(const std::string& topic, const std::string& payload, bool retained)>
        message;
    std::function<void(const std::string& line)> log;  // connection changes, once each
  };
  struct Stats {
    uint64_t published = 0;
    uint64_t dropped = 0;  // not connected, or over the unsent limit
    uint64_t connects = 0;
  };
  // Messages handed to the library and not yet written to the socket.
  static constexpr uint64_t kMaxUnsent = 1000;

  static Expected<std::unique_ptr<MqttClient>, std::string> start(const MqttUrl& url,
                                                                  const std::string& clientId,
                                                                  const MqttWill& will,
                                                                  Handlers handlers);
  // Says the will itself (a clean stop is an end like any other) if
  // connected, disconnects, joins the thread: within about a second
  // whatever the broker does.
  ~MqttClient();
  MqttClient(const MqttClient&) = delete;
  MqttClient& operator=(const MqttClient&) = delete;

  // Thread-safe and non-blocking; false when dropped.
  bool publish(const std::string& topic, const std::string& payload, bool retain = false,
               int qos = 0);
  // Thread-safe; the client's thread only subscribes after it is connected.
  void subscribe(const std::string& pattern);
  bool connected() const { return connected_; }
  Stats stats() const;

 private:
  MqttClient(const MosquittoLibrary& lib, MqttUrl url, MqttWill will, mosquitto* handle,
             Handlers handlers);
  void run();
  bool reachable();
  // Why a connection could not be made, in words (a TLS failure explained).
  std::string cannotConnect(int rc) const;
  void waitBackoff();
  void report(const std::string& line);
  static void onConnect(mosquitto*, void* self, int rc);
  static void onMessage(mosquitto*, void* self, const mosquitto_message* message);
  static void onPublish(mosquitto*, void* self, int mid);

  const MosquittoLibrary& lib_;
  const MqttUrl url_;
  mosquitto* handle_;
  const Handlers handlers_;
  const MqttWill will_;
  std::atomic<bool> connected_{false};
  std::atomic<bool> stopping_{false};
  std::atomic<uint64_t> published_{0}, written_{0}, dropped_{0}, connects_{0};
  std::chrono::seconds backoff_{1};
  std::string lastReport_;  // client thread only
  std::mutex mutex_;        // the stop's wake-up
  std::condition_variable wake_;
  std::thread thread_;
};

}  // namespace wircam::recorder
