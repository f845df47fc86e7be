#include "mqtt_broker.h"

#include <mosquitto.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <thread>

#include "free_port.h"
#include "wait_for.h"

namespace wircam::testing {

namespace fs = std::filesystem;

namespace {}  // namespace

MosquittoBroker::MosquittoBroker(const std::string& user, const std::string& password,
                                 const fs::path& tls) {
  static int count = 0;
  folder_ = fs::temp_directory_path() /
            ("wirc-mosquitto-" + std::to_string(getpid()) + "-" + std::to_string(++count));
  fs::remove_all(folder_);
  fs::create_directories(folder_);
  std::string access = "allow_anonymous true\n";
  if (!user.empty()) {
    auto passwords = folder_ / "passwords";
    std::string command = "mosquitto_passwd -b -c " + passwords.string() + " '" + user + "' '" +
                          password + "' > /dev/null 2>&1";
    if (std::system(command.c_str()) != 0) return;
    access = "allow_anonymous false\npassword_file " + passwords.string() + "\n";
  }
  // The free port may be taken by a test running beside this one before
  // mosquitto binds it: then it exits, and another port is tried.
  for (int attempt = 0; attempt < 5 && !running(); ++attempt) {
    port_ = freeLoopbackPort();
    std::ofstream config(folder_ / "mosquitto.conf");
    config << "listener " << port_ << " 127.0.0.1\npersistence false\n" << access;
    if (!tls.empty()) {
      tlsPort_ = freeLoopbackPort();
      config << "listener " << tlsPort_ << " 127.0.0.1\ncafile " << (tls / "ca.pem").string()
             << "\ncertfile " << (tls / "server.pem").string() << "\nkeyfile "
             << (tls / "server.key").string() << "\n";
    }
    config.close();
    start();
  }
}

MosquittoBroker::~MosquittoBroker() {
  kill();
  fs::remove_all(folder_);
}

std::string MosquittoBroker::url(const std::string& credentials) const {
  return "mqtt://" + (credentials.empty() ? "" : credentials + "@") +
         "127.0.0.1:" + std::to_string(port_);
}

void MosquittoBroker::kill() {
  if (pid_ <= 0) return;
  ::kill(pid_, SIGKILL);
  waitpid(pid_, nullptr, 0);
  pid_ = -1;
}

bool MosquittoBroker::start() {
  std::string config = (folder_ / "mosquitto.conf").string();
  fs::path log = folder_ / "mosquitto.log";
  std::error_code error;
  auto logged = fs::exists(log) ? fs::file_size(log, error) : 0;  // earlier runs' lines
  pid_ = fork();
  if (pid_ == 0) {
    if (!freopen(log.c_str(), "a", stdout) || !freopen(log.c_str(), "a", stderr)) _exit(126);
    execlp("mosquitto", "mosquitto", "-c", config.c_str(), nullptr);
    _exit(127);
  }
  // Its own word that it listens: something else may answer on the port.
  for (int i = 0; i < 250; ++i) {
    if (waitpid(pid_, nullptr, WNOHANG) == pid_) {
      pid_ = -1;  // exited: the port was taken
      return false;
    }
    std::ifstream in(log);
    in.seekg(static_cast<std::streamoff>(logged));
    std::string text((std::istreambuf_iterator<char>(in)), {});
    if (text.find(" running") != std::string::npos) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return false;
}

MqttProbe::MqttProbe(uint16_t port, const std::string& pattern) : pattern_(pattern) {
  mosquitto_lib_init();
  handle_ = mosquitto_new(nullptr, true, this);
  mosquitto_message_callback_set(handle_, [](mosquitto*, void* self, const mosquitto_message* m) {
    auto* probe = static_cast<MqttProbe*>(self);
    std::lock_guard lock(probe->mutex_);
    probe->messages_.push_back(
        {m->topic, std::string(static_cast<const char*>(m->payload), m->payloadlen), m->retain});
  });
  // Subscribed again at every connection (the broker may restart).
  mosquitto_connect_callback_set(handle_, [](mosquitto* handle, void* self, int rc) {
    if (rc == 0)
      mosquitto_subscribe(handle, nullptr, static_cast<MqttProbe*>(self)->pattern_.c_str(), 1);
  });
  mosquitto_reconnect_delay_set(handle_, 1, 1, false);
  mosquitto_loop_start(handle_);
  mosquitto_connect_async(handle_, "127.0.0.1", port, 10);
}

MqttProbe::~MqttProbe() {
  mosquitto_disconnect(handle_);
  mosquitto_loop_stop(handle_, false);
  mosquitto_destroy(handle_);
}

void MqttProbe::publish(const std::string& topic, const std::string& payload, bool retain) {
  mosquitto_publish(handle_, nullptr, topic.c_str(), static_cast<int>(payload.size()),
                    payload.data(), 1, retain);
}

std::vector<MqttMessage> MqttProbe::messages(const std::string& topic) const {
  std::lock_guard lock(mutex_);
  std::vector<MqttMessage> found;
  for (const auto& m : messages_)
    if (topic.empty() || m.topic == topic) found.push_back(m);
  return found;
}

bool MqttProbe::waitFor(const std::string& topic,
                        const std::function<bool(const MqttMessage&)>& match,
                        std::chrono::milliseconds timeout) {
  auto end = std::chrono::steady_clock::now() + patience(timeout);
  do {
    for (const auto& m : messages(topic))
      if (match(m)) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  } while (std::chrono::steady_clock::now() < end);
  return false;
}

}  // namespace wircam::testing
