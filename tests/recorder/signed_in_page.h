// A wirc-recorder with its web server (and by default the access token)
// and Debian's chromium signed in to it, recording a simulated car, for the
// tests that use the page as its users do. Screenshots go under the build
// tree.
#pragma once

#include <chrono>
#include <filesystem>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "devices/wirc/device.h"
#include "devtools_page.h"
#include "follow_scene.h"
#include "recorder_process.h"

namespace wircam::testing {

// The simulator's follow scene (a car and its AprilTag target) on a device
// on an ephemeral port, the scene kept so a test can see where the car is.
struct FollowedCar {
  std::shared_ptr<sim::FollowScene> scene;
  std::unique_ptr<wirc::Device> device;
  FollowedCar();
};

inline constexpr const char* kToken = "0123456789abcdef0123456789abcdef";

// The simulated car's channels (pulses[kSteering] > 1500: left).
inline constexpr size_t kSteering = 0, kThrottle = 1;
// Both channels at neutral on the simulated device.
bool atNeutral(const wirc::Device& device);
// How long until they are (3 s at most), polled every 2 ms: what the
// drive tests measure a dead-man or a closed page by.
std::chrono::milliseconds untilNeutral(const wirc::Device& device);

// A page's drive channel (window.probe, a WebSocket or a WebRTC data
// channel, whose answers land in window.answer) sends full ahead every
// 100 ms, then junk: the junk is answered with its reason and the car is at
// neutral at once, not when the dead-man would lapse.
void expectJunkStopsTheCarAtOnce(DevToolsPage& page, const wirc::Device& device);
// The page, driving, hangs (its scripts stop): the dead-man stops the car
// within 250 ms of the last command, a command period (100 ms) being the
// most that passes between them, and 100 ms for the polling under load.
void expectAHungPageStopsTheCar(DevToolsPage& page, const wirc::Device& device);
// The hung page comes back, drives again, and its tab is closed: neutral
// within a dead-man and a command period.
void expectAClosedTabStopsTheCar(DevToolsPage& page, const wirc::Device& device);

// build/tests/recorder/NAME
std::filesystem::path shotPath(const std::string& name);

struct SignedInPage {
  RecorderProcess recorder;
  std::string url;  // "http://127.0.0.1:PORT/"
  std::unique_ptr<DevToolsPage> page;
  // Records from 127.0.0.1:port with `extra`; `profile` names chromium's
  // profile folder.
  SignedInPage(uint16_t port, std::vector<std::string> extra, const std::string& profile,
               bool withToken = true);
  bool clickOn(const std::string& selector) { return page->clickOn(selector); }
};

}  // namespace wircam::testing
