// The simulated vehicles the recorder tests record from, on loopback with
// ephemeral ports.
#pragma once

#include <memory>

#include "devices/wirc/device.h"
#include "follow_scene.h"
#include "held_port.h"
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
