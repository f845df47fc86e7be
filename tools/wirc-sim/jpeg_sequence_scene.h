// A scene that shows a fixed sequence of JPEG files, byte for byte, looping:
// `wirc-sim --frames DIR`, and the frames tests compare against.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "common/expected.h"
#include "devices/wirc/device.h"

namespace wircam::sim {

class JpegSequenceScene : public wirc::DeviceScene {
 public:
  explicit JpegSequenceScene(std::vector<std::vector<uint8_t>> frames);

  // Every *.jpg / *.jpeg file of `directory`, in name order.
  static Expected<std::vector<std::vector<uint8_t>>, std::string> loadFolder(
      const std::string& directory);

  void advance(wirc::DeviceClock::time_point now, const wirc::ChannelOutputs& outputs) override;
  std::vector<uint8_t> renderJpeg(int camera) override;

 private:
  std::vector<std::vector<uint8_t>> frames_;
  std::map<int, size_t> next_;  // per camera: each sees the whole sequence
};

}  // namespace wircam::sim
