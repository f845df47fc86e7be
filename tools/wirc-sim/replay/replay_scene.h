// `wirc-sim --replay PATH`: a recorded drive shown as the device's camera,
// each frame at its recorded time (scaled by --speed; an outage stays an
// outage, up to kMaxGap), the recorded battery in the status, and every PCD
// the device obeys written with the frame that was on screen when it came
// (--commands-out): what a controller commanded on that footage.
// Called on the device thread only; summary() once the device has stopped.
#pragma once

#include <chrono>
#include <cstdio>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "devices/wirc/device.h"
#include "replay/recorded_drive.h"

namespace wircam::sim {

class ReplayScene : public wirc::DeviceScene {
 public:
  // A longer pause between two frames (two drives of a day, hours apart) is
  // replayed as this long: an outage still, not a wait.
  static constexpr std::chrono::seconds kMaxGap{10};

  struct Options {
    double speed = 1;  // 2: twice as fast
    bool loop = false;
    std::string commandsOut;      // a JSON Lines file, or none
    std::function<void()> ended;  // after the last frame (without loop)
    std::function<void(const std::string&)> log;
  };
  // Errors: the commands file cannot be written.
  static Expected<std::unique_ptr<ReplayScene>, std::string> create(
      std::unique_ptr<RecordedDrive> drive, Options options);
  ~ReplayScene() override;

  void advance(wirc::DeviceClock::time_point now, const wirc::ChannelOutputs& outputs) override;
  std::vector<uint8_t> renderJpeg(int camera) override;
  std::optional<wirc::DeviceClock::duration> frameInterval() override;
  std::optional<uint16_t> batteryMillivolts() override;
  void pcdReceived(wirc::DeviceClock::time_point at, const wirc::ChannelValues& values) override;
  bool waitsForViewer() const override { return true; }

  // "replayed 150 frames of 1 segment (CAMERA), 3 PCD written to FILE".
  std::string summary() const;

 private:
  ReplayScene(std::unique_ptr<RecordedDrive> drive, Options options);
  void sayNotes();

  std::unique_ptr<RecordedDrive> drive_;
  Options options_;
  std::FILE* commands_ = nullptr;
  std::optional<RecordedDrive::Frame> shown_, coming_;
  uint64_t framesShown_ = 0, commandsWritten_ = 0, loops_ = 0;
  bool endSaid_ = false;
  std::optional<wirc::DeviceClock::time_point> started_;
};

}  // namespace wircam::sim
