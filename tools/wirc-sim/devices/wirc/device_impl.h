// The inside of a WiRC device (wirc::Device): its connections, streams and
// the state the device thread keeps. Shared by device.cpp (sockets, timers,
// the loop) and device_commands.cpp (what each message of a transmitter
// does).
#pragma once

#include <netinet/in.h>

#include <array>
#include <atomic>
#include <deque>
#include <list>
#include <map>
#include <mutex>
#include <optional>
#include <span>
#include <thread>

#include "devices/wirc/device.h"
#include "wirc/message_stream_parser.h"
#include "wirc/mjpeg_packet.h"

namespace wircam::wirc {

namespace device_detail {

// One TCP connection of a transmitter, from accept to close.
struct Connection {
  UniqueFd fd;
  SocketAddress peer;
  uint8_t id = 0;
  uint64_t order = 0;  // the lowest among the logged-in is the "first" transmitter
  MessageStreamParser parser;
  std::optional<Tl> login;
  bool ccfgSeen = false;
  bool fcfgSeen = false;
  bool started = false;  // WST sent
  bool closing = false;  // closed at the end of this loop turn
  std::string closeReason;
};

struct StreamKey {
  uint8_t connection;
  uint8_t camera;
  auto operator<=>(const StreamKey&) const = default;
};

template <class... Ts>
struct Overloaded : Ts... {
  using Ts::operator()...;
};
template <class... Ts>
Overloaded(Ts...) -> Overloaded<Ts...>;

}  // namespace device_detail

class Device::Impl {
  using Connection = device_detail::Connection;
  using StreamKey = device_detail::StreamKey;

 public:
  Impl(DeviceConfig config, std::shared_ptr<DeviceScene> scene, Logger logger)
      : config_(std::move(config)),
        scene_(std::move(scene)),
        logger_(std::move(logger)),
        name_(config_.name),
        batteryMillivolts_(config_.batteryMillivolts) {
    periods_.fill(20000);
    failsafe_ = neutralChannels();
  }

  std::optional<std::string> open();
  void run();
  void requestStop();

  uint16_t port_ = 0;
  uint16_t controlPort_ = 0;
  std::thread thread_;

  // Guards the copies that other threads read; the device thread alone
  // writes them, and holds the lock only to copy.
  mutable std::mutex mutex_;
  DeviceStats stats_;
  ChannelOutputs outputs_;
  std::string publishedName_;
  std::deque<DeviceClock::time_point> pcdArrivals_;

 private:
  void log(const std::string& text) {
    if (logger_) logger_(text);
  }
  std::optional<std::string> openListener();
  void runTimers(DeviceClock::time_point now);
  int pollTimeoutMs(DeviceClock::time_point now) const;
  void acceptConnection();
  void readConnection(Connection& connection);
  void readDiscovery();
  // The PCD waiting in the socket (up to 256), each at its arrival time.
  void readPcds();
  void readPcd(std::span<const uint8_t> datagram, const sockaddr_in& from,
               DeviceClock::time_point now);
  void handleMessage(Connection& connection, const Expected<Message, ProtocolError>& result);
  void handle(Connection& c, const Tl& m);
  void handle(Connection& c, const Ccfg& m);
  void handle(Connection& c, const Fcfg& m);
  void handle(Connection& c, const Dcfg& m);
  void handle(Connection& c, const Wcfg& m);
  void handle(Connection& c, const Tlr& m);
  void handle(Connection& c, const Areq& m);
  void handle(Connection& c, const Fwup& m);
  void handle(Connection& c, const Stst& m);
  void handle(Connection& c, const Est& m);
  void handle(Connection& c, const Extout& m);
  void sendMessage(Connection& connection, const Message& message);
  void sendError(Connection& connection, uint8_t command, ErrorCode code);
  bool requireLogin(Connection& connection, Command command);
  bool requireStarted(Connection& connection, Command command);
  bool requireFirst(Connection& connection, Command command);
  bool isFirst(const Connection& connection) const;
  void maybeStart(Connection& connection);
  void giveControl(Connection& to);
  Connection* findConnection(uint8_t id);
  Connection* controller() { return controller_ ? findConnection(*controller_) : nullptr; }
  void enterFailsafe(const std::string& why);
  void closeConnection(Connection& connection, std::string reason);
  void sweepClosed();
  void restart();
  void tickFrame(DeviceClock::time_point now);
  void sendStatus();
  void publish();
  uint8_t allocateId();

  DeviceConfig config_;
  std::shared_ptr<DeviceScene> scene_;
  Logger logger_;
  std::atomic<bool> stopping_{false};
  UniqueFd wake_;
  UniqueFd listener_;
  UniqueFd discovery_;
  UniqueFd control_;
  UniqueFd video_;
  UniqueFd stray_;
  std::list<Connection> connections_;
  std::map<StreamKey, StreamSender> streams_;
  ChannelValues periods_{};
  ChannelValues failsafe_{};
  ChannelOutputs localOutputs_;
  std::optional<uint8_t> controller_;
  DeviceClock::time_point controlDeadline_;  // PCD must come before this
  std::optional<DeviceClock::time_point> lastPcd_;
  DeviceClock::time_point nextPsd_;
  DeviceClock::time_point nextFrame_;
  std::optional<DeviceClock::time_point> lastTick_;
  std::optional<DeviceClock::time_point> restartDone_;
  std::string name_;
  std::string pendingName_;
  double batteryMillivolts_;
  uint8_t nextId_ = 1;
  uint64_t nextOrder_ = 0;
  DeviceStats localStats_;
  std::array<uint8_t, kMaxDatagramSize> buffer_{};
};

}  // namespace wircam::wirc
