// What the camera isolation and fault tests check of a running recorder:
// a camera's entry in /api/cameras, the frames its finished files hold
// (index.json), and a SIGINT that ends the recorder within 3 s.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>

#include "http_fetch.h"
#include "misbehaving_peers.h"
#include "recorder_process.h"

namespace wircam::testing {

// Logs in (WST), reports its status once, and never sends a frame: the
// recorder logs in again after each link timeout, and still no frame.
struct SilentCamera {
  ScriptedPeer peer;
  SilentCamera() { peer.play({.chunks = {peer.wst()}, .statusReports = 1}); }
  std::string device() const { return "127.0.0.1:" + std::to_string(peer.port()); }
};

// The recorder's name of camera 0 of the device at 127.0.0.1:port.
std::string cameraName(uint16_t port);

// The frames of `camera` in the index's (finished) segments.
uint64_t indexedFrames(const std::filesystem::path& out, const std::string& camera);

// /api/cameras' entry of `camera` from the recorder at `url`, or null
// (`headers`: a token's, say).
nlohmann::json cameraEntry(const std::string& url, const std::string& camera,
                           const Headers& headers = {});

// /api/status's stream entry of `camera`, or null.
nlohmann::json streamEntry(const std::string& url, const std::string& camera,
                           const Headers& headers = {});

// /api/status's frames of `camera`: 0 until it is listed.
uint64_t framesOf(const std::string& url, const std::string& camera, const Headers& headers = {});

// SIGINT ends the recorder with exit 0 within 3 s, `meanwhile` done just
// after the signal.
void expectSigintEndsItWithinThreeSeconds(RecorderProcess& recorder,
                                          const std::function<void()>& meanwhile = {});

}  // namespace wircam::testing
