// The web server's per-camera state, shared by its route files: the feed of
// a camera's frames and the streaming responses that take them.
#pragma once

#include <libsoup/soup.h>

#include <atomic>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "camera/frame_tap.h"
#include "http/http_server.h"
#include "recording/playback_stream.h"

namespace wircam::recorder {

// One open streaming response: an MJPEG viewer, an event listener, or a
// recording being replayed (which goes when the viewer does).
struct HttpServer::Client {
  SoupServerMessage* message;
  int inFlight = 0;  // chunks appended but not yet written to the socket
  gulong wroteHandler = 0, finishedHandler = 0;
  std::unique_ptr<PlaybackStream> playback;
};

struct HttpServer::CameraFeed {
  std::string name;
  FrameTap* frames;
  int listener = 0;
  std::vector<std::unique_ptr<Client>> clients;
  std::atomic<int> clientCount{0};       // read on the streaming thread
  std::atomic<int> width{0}, height{0};  // of the last frame, for the overlay
  // The newest frame as the camera sent it, for snapshots (the streaming
  // thread swaps it, the main loop reads it).
  std::mutex latestMutex;
  GstBuffer* latest = nullptr;
  nlohmann::json detections = nlohmann::json::array();  // the last ones
};

}  // namespace wircam::recorder
