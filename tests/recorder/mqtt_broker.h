// A real mosquitto broker on a loopback port of its own, and a real MQTT
// client (libmosquitto) that records what it receives: the MQTT tests'
// two ends.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <functional>
#include <mutex>
#include <string>
#include <vector>

struct mosquitto;

namespace wircam::testing {

class MosquittoBroker {
 public:
  // With a user, only that user with that password may connect. With
  // `tls` (a folder of makeCertificates()), a second listener speaks TLS
  // with its server certificate, on tlsPort().
  explicit MosquittoBroker(const std::string& user = "", const std::string& password = "",
                           const std::filesystem::path& tls = {});
  ~MosquittoBroker();
  MosquittoBroker(const MosquittoBroker&) = delete;
  MosquittoBroker& operator=(const MosquittoBroker&) = delete;

  uint16_t port() const { return port_; }
  uint16_t tlsPort() const { return tlsPort_; }
  std::string url(const std::string& credentials = "") const;
  bool running() const { return pid_ > 0; }
  void kill();   // SIGKILL: nothing said, nothing kept
  bool start();  // again, on the same port; true once it accepts connections

 private:
  std::filesystem::path folder_;
  uint16_t port_ = 0, tlsPort_ = 0;
  pid_t pid_ = -1;
};

struct MqttMessage {
  std::string topic, payload;
  bool retained = false;
};

class MqttProbe {
 public:
  // Subscribes to `pattern` on the broker at 127.0.0.1:port.
  MqttProbe(uint16_t port, const std::string& pattern);
  ~MqttProbe();
  MqttProbe(const MqttProbe&) = delete;
  MqttProbe& operator=(const MqttProbe&) = delete;

  void publish(const std::string& topic, const std::string& payload, bool retain = false);
  // The messages so far on `topic` (all with an empty topic).
  std::vector<MqttMessage> messages(const std::string& topic = "") const;
  // Waits for a message on `topic` that `match` accepts (`timeout` stretched
  // under a sanitizer).
  bool waitFor(const std::string& topic, const std::function<bool(const MqttMessage&)>& match,
               std::chrono::milliseconds timeout);

 private:
  const std::string pattern_;
  mosquitto* handle_;
  mutable std::mutex mutex_;
  std::vector<MqttMessage> messages_;
};

}  // namespace wircam::testing
