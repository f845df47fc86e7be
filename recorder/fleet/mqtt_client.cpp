#include "fleet/mqtt_client.h"

#include <poll.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>

#include "common/socket.h"
#include "fleet/mosquitto_library.h"

namespace wircam::recorder {

namespace {

constexpr int kKeepaliveSeconds = 10;
constexpr std::chrono::seconds kMaxBackoff{30};
constexpr int kReachTimeoutMs = 2000;
// The longest wait between two keepalive checks of the library.
constexpr int kServeTimeoutMs = 1000;
// How long a write the library holds back waits before it is tried again.
constexpr int kHeldWriteRetryMs = 10;

}  // namespace

MqttClient::MqttClient(const MosquittoLibrary& lib, MqttUrl url, MqttWill will, mosquitto* handle,
                       Handlers handlers)
    : lib_(lib),
      url_(std::move(url)),
      handle_(handle),
      handlers_(std::move(handlers)),
      will_(std::move(will)),
      wakeFd_(eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK)) {}

Expected<std::unique_ptr<MqttClient>, std::string> MqttClient::start(const MqttUrl& url,
                                                                     const std::string& clientId,
                                                                     const MqttWill& will,
                                                                     Handlers handlers) {
  auto library = mosquittoLibrary();
  if (!library) return unexpected(library.error());
  const MosquittoLibrary& lib = **library;
  mosquitto* handle = lib.create(clientId.c_str(), true, nullptr);
  if (!handle) return unexpected(std::string("cannot create an MQTT client"));
  std::unique_ptr<MqttClient> client(new MqttClient(lib, url, will, handle, std::move(handlers)));
  if (!client->wakeFd_.valid())
    return unexpected("cannot create the MQTT client's wake-up: " + errnoText(errno));
  lib.userDataSet(handle, client.get());
  lib.threadedSet(handle, true);
  if (!url.user.empty() &&
      lib.usernamePwSet(handle, url.user.c_str(),
                        url.password.empty() ? nullptr : url.password.c_str()) != MOSQ_ERR_SUCCESS)
    return unexpected(std::string("the MQTT user name or password is not valid UTF-8"));
  if (url.tls) {
    // The broker's certificate is checked against the CA file (or the
    // system's CAs) and its host name; a handshake that fails is said.
    int rc = url.caFile.empty()
                 ? lib.tlsSet(handle, nullptr, "/etc/ssl/certs", nullptr, nullptr, nullptr)
                 : lib.tlsSet(handle, url.caFile.c_str(), nullptr, nullptr, nullptr, nullptr);
    if (rc != MOSQ_ERR_SUCCESS)
      return unexpected("--mqtt-cafile " + url.caFile + ": " + lib.strerror(rc) +
                        " (a PEM file of the CA that signed the broker's certificate)");
  }
  if (!will.topic.empty() &&
      lib.willSet(handle, will.topic.c_str(), static_cast<int>(will.payload.size()),
                  will.payload.data(), 1, true) != MOSQ_ERR_SUCCESS)
    return unexpected("cannot set the MQTT last will on '" + will.topic + "'");
  lib.connectCallbackSet(handle, onConnect);
  lib.messageCallbackSet(handle, onMessage);
  lib.publishCallbackSet(handle, onPublish);
  client->thread_ = std::thread([c = client.get()] { c->run(); });
  return client;
}

MqttClient::~MqttClient() {
  stopping_ = true;
  wake();
  if (thread_.joinable()) thread_.join();
  lib_.destroy(handle_);
}

void MqttClient::report(const std::string& line) {
  // Each change once: a broker that stays away is not a line per retry.
  if (line == lastReport_) return;
  lastReport_ = line;
  if (handlers_.log) handlers_.log(line);
}

bool MqttClient::reachable() {
  // mosquitto_connect blocks until TCP gives up on a host that never
  // answers; a bounded probe first keeps stops and retries prompt.
  auto address = SocketAddress::resolve(url_.host, url_.port);
  if (!address) return report("MQTT broker " + url_.host + ": " + address.error()), false;
  auto socket = startConnectTcp(*address);
  if (!socket) return report("MQTT broker " + address->toString() + ": " + socket.error()), false;
  pollfd wait{.fd = socket->get(), .events = POLLOUT, .revents = 0};
  for (int waited = 0; waited < kReachTimeoutMs && !stopping_; waited += 100)
    if (poll(&wait, 1, 100) != 0) break;
  int error = wait.revents ? pendingError(socket->get()) : ETIMEDOUT;
  if (error != 0)
    report("MQTT broker " + address->toString() + " cannot be reached (" + errnoText(error) +
           "); retrying with backoff, the recording goes on");
  return error == 0;
}

std::string MqttClient::cannotConnect(int rc) const {
  std::string where = "MQTT broker " + url_.host + ":" + std::to_string(url_.port) + ": ";
  if (rc != MOSQ_ERR_TLS) return where + lib_.strerror(rc);
  std::string ca = url_.caFile.empty() ? "the system's CAs" : "--mqtt-cafile " + url_.caFile;
  return where + "the TLS handshake failed: the broker's certificate is not one " + ca +
         " signed for " + url_.host +
         ", or the broker does not speak TLS there; retrying with backoff, the recording goes on";
}

void MqttClient::wake() {
  uint64_t one = 1;
  [[maybe_unused]] auto written = write(wakeFd_.get(), &one, sizeof one);
}

void MqttClient::takeWake() {
  uint64_t count;
  [[maybe_unused]] auto taken = read(wakeFd_.get(), &count, sizeof count);
}

void MqttClient::waitBackoff() {
  using namespace std::chrono;
  auto until = steady_clock::now() + backoff_;
  pollfd wakeUp{.fd = wakeFd_.get(), .events = POLLIN, .revents = 0};
  while (!stopping_) {
    auto left = duration_cast<milliseconds>(until - steady_clock::now()).count();
    if (left <= 0) break;
    poll(&wakeUp, 1, static_cast<int>(left));
    takeWake();
  }
  backoff_ = std::min(backoff_ * 2, kMaxBackoff);
}

int MqttClient::serve(int timeoutMs) {
  int socket = lib_.socket(handle_);
  if (socket < 0) return MOSQ_ERR_NO_CONN;
  // The library holds what it queued until its TLS handshake is done, and
  // says nothing of it: when a write to a socket poll() called writable
  // left something queued, the next waits a moment for the broker's answer
  // alone, rather than spin on a socket that is always writable.
  bool held = writeWaits_;
  writeWaits_ = false;
  short events = POLLIN;
  if (!held && lib_.wantWrite(handle_)) events |= POLLOUT;
  pollfd waits[2] = {{.fd = socket, .events = events, .revents = 0},
                     {.fd = wakeFd_.get(), .events = POLLIN, .revents = 0}};
  if (poll(waits, 2, held ? kHeldWriteRetryMs : timeoutMs) < 0 && errno != EINTR)
    return MOSQ_ERR_ERRNO;
  bool woken = waits[1].revents != 0;
  if (woken) takeWake();
  if (waits[0].revents & (POLLIN | POLLERR | POLLHUP | POLLNVAL)) {
    int rc = lib_.loopRead(handle_, 1);
    if (rc != MOSQ_ERR_SUCCESS || lib_.socket(handle_) < 0) return rc;
  }
  // Woken for a publish, the socket is tried at once: it is most often
  // writable, and one poll fewer.
  bool writable = waits[0].revents & POLLOUT;
  if ((writable || woken || held) && lib_.wantWrite(handle_)) {
    int rc = lib_.loopWrite(handle_, 1);
    if (rc != MOSQ_ERR_SUCCESS || lib_.socket(handle_) < 0) return rc;
    writeWaits_ = (writable || held) && lib_.wantWrite(handle_);
  }
  return lib_.loopMisc(handle_);
}

void MqttClient::run() {
  bool session = false;  // a TCP connection the library drives (CONNACK pending or connected)
  while (!stopping_) {
    if (!session) {
      if (!reachable()) {
        waitBackoff();
        continue;
      }
      int rc = lib_.connect(handle_, url_.host.c_str(), url_.port, kKeepaliveSeconds);
      if (rc != MOSQ_ERR_SUCCESS) {
        report(cannotConnect(rc));
        waitBackoff();
        continue;
      }
      session = true;
    }
    int rc = serve(kServeTimeoutMs);
    if (rc != MOSQ_ERR_SUCCESS) {
      session = false;
      if (connected_.exchange(false))
        report("lost the MQTT broker " + url_.host + ":" + std::to_string(url_.port) + " (" +
               lib_.strerror(rc) + "); reconnecting with backoff");
      else
        report(cannotConnect(rc));  // the TLS handshake comes after mosquitto_connect
      waitBackoff();
    }
  }
  if (connected_) {
    // The last word, as the will would say it; then a clean goodbye.
    if (!will_.topic.empty())
      lib_.publish(handle_, nullptr, will_.topic.c_str(), static_cast<int>(will_.payload.size()),
                   will_.payload.data(), 1, true);
    for (int turn = 0; turn < 5 && lib_.wantWrite(handle_); ++turn) serve(100);
    lib_.disconnect(handle_);
    serve(100);
    connected_ = false;
  }
}

void MqttClient::onConnect(mosquitto*, void* self, int rc) {
  auto* client = static_cast<MqttClient*>(self);
  if (rc != 0) {
    client->report(std::string("the MQTT broker refused the connection: ") +
                   client->lib_.connackString(rc) + "; retrying with backoff");
    client->lib_.disconnect(client->handle_);
    return;
  }
  // What an earlier session left unsent is gone with it.
  client->written_ = client->published_.load();
  client->connected_ = true;
  client->backoff_ = std::chrono::seconds(1);
  ++client->connects_;
  client->report("connected to the MQTT broker " + client->url_.host + ":" +
                 std::to_string(client->url_.port));
  if (client->handlers_.connected) client->handlers_.connected(*client);
}

void MqttClient::onMessage(mosquitto*, void* self, const mosquitto_message* message) {
  auto* client = static_cast<MqttClient*>(self);
  if (!client->handlers_.message || !message->topic) return;
  std::string payload(static_cast<const char*>(message->payload),
                      message->payload ? static_cast<size_t>(message->payloadlen) : 0);
  client->handlers_.message(message->topic, payload, message->retain);
}

void MqttClient::onPublish(mosquitto*, void* self, int) {
  ++static_cast<MqttClient*>(self)->written_;
}

bool MqttClient::publish(const std::string& topic, const std::string& payload, bool retain,
                         int qos) {
  // Counted before it is handed over: the library may report it written
  // (onPublish, on another thread) before mosquitto_publish returns, and
  // written_ must never pass published_ (the difference would wrap, and
  // every message would be dropped as "too many unsent").
  uint64_t before = published_++, written = written_;
  uint64_t unsent = before > written ? before - written : 0;
  if (!connected_ || unsent >= kMaxUnsent) return --published_, ++dropped_, false;
  int rc = lib_.publish(handle_, nullptr, topic.c_str(), static_cast<int>(payload.size()),
                        payload.data(), qos, retain);
  if (rc != MOSQ_ERR_SUCCESS) return --published_, ++dropped_, false;
  wake();
  return true;
}

void MqttClient::subscribe(const std::string& pattern) {
  lib_.subscribe(handle_, nullptr, pattern.c_str(), 1);
  wake();
}

MqttClient::Stats MqttClient::stats() const {
  return {.published = published_, .dropped = dropped_, .connects = connects_};
}

}  // namespace wircam::recorder
