// An MQTT client on a thread of its own (libmosquitto, opened on the first
// start), for the recorder's fleet topics. Publishing never waits: it hands
// the message to the library, or drops and counts it while the broker is
// away or too much is still unsent. The connection is made again with backoff (1 s doubling to
// 30 s) for as long as the client lives, and every wait is bounded, so a
// dead broker never holds up a recording or its stop.
//
// The thread waits with poll(), not with mosquitto_loop(): that one's
// select() refuses any socket numbered 1024 or more, and a recorder of a
// hundred cameras holds more files than that, so a broker it lost was
// never joined again.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include "common/expected.h"
#include "common/socket.h"
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
  // One wait on the broker's socket (at most `timeoutMs`) and the library's
  // reads, writes and keepalive that it calls for; a mosquitto error code.
  int serve(int timeoutMs);
  void wake();
  void takeWake();
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
  std::string lastReport_;   // client thread only
  bool writeWaits_ = false;  // client thread only: see serve()
  const UniqueFd wakeFd_;    // an eventfd: something to publish, or the stop
  std::thread thread_;
};

}  // namespace wircam::recorder
