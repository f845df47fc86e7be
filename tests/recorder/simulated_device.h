// The simulated vehicles the recorder tests record from, on loopback with
// ephemeral ports.
#pragma once

#include <sys/socket.h>

#include <memory>

#include "common/socket.h"
#include "devices/wirc/device.h"
#include "follow_scene.h"
#include "jpeg_sequence_scene.h"
#include "scene_frames.h"

namespace wircam::testing {

// Known distinct frames at `fps`; `port` 0 picks one.
inline std::unique_ptr<wirc::Device> startSequenceDevice(uint16_t port = 0, double fps = 15,
                                                         wirc::Impairments impairments = {}) {
  auto device = wirc::Device::start(
      {.port = port, .fps = fps, .fragmentSize = 8000, .impairments = impairments},
      std::make_shared<sim::JpegSequenceScene>(sceneFrames()));
  return device ? std::move(*device) : nullptr;
}

// The port of a device switched off, kept from every other socket until
// the device comes back on it: the parallel tests' own ephemeral sockets
// took a freed port now and then, and the device could not come back.
// TCP bound but not listening (a connection is refused, as by a vehicle
// that is off) and UDP (its discovery) bound.
class HeldPort {
 public:
  explicit HeldPort(uint16_t port) : port_(port) {
    auto address = SocketAddress::loopback(port);
    tcp_ = UniqueFd(::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0));
    int on = 1;  // over its connections' TIME_WAIT, as the device's listener
    setsockopt(tcp_.get(), SOL_SOCKET, SO_REUSEADDR, &on, sizeof on);
    if (::bind(tcp_.get(), address.raw(), address.size()) != 0) tcp_.reset();
    if (auto udp = bindUdp(address)) udp_ = std::move(*udp);
  }
  uint16_t port() const { return port_; }
  void release() {
    tcp_.reset();
    udp_.reset();
  }

 private:
  uint16_t port_;
  UniqueFd tcp_, udp_;
};

// `device` off, its port held.
inline HeldPort switchOff(std::unique_ptr<wirc::Device>& device) {
  uint16_t port = device->port();
  device.reset();
  return HeldPort(port);
}

// A device of known distinct frames on the held port again.
inline std::unique_ptr<wirc::Device> switchOn(HeldPort& held) {
  held.release();
  return startSequenceDevice(held.port());
}

// The follow scene: a car with an AprilTag (tag36h11, id 0) in front of it.
inline std::unique_ptr<wirc::Device> startFollowDevice() {
  auto scene = sim::FollowScene::create({});
  if (!scene) return nullptr;
  auto device = wirc::Device::start({.port = 0, .fragmentSize = 8000},
                                    std::shared_ptr<sim::FollowScene>(std::move(*scene)));
  return device ? std::move(*device) : nullptr;
}

}  // namespace wircam::testing
