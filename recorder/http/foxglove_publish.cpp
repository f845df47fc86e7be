// FoxgloveServer's outgoing messages: each camera's frames, tags,
// telemetry, log and poses to the clients subscribed to them, while their
// sockets have room.
#include <linux/sockios.h>
#include <sys/ioctl.h>
#include <sys/socket.h>

#include <algorithm>

#include "foxglove/annex_b.h"
#include "foxglove/foxglove_messages.h"
#include "gst_h264_start.h"
#include "gst_scoped.h"
#include "http/foxglove_clients.h"
#include "http/foxglove_server.h"

namespace wircam::recorder {

namespace {

int64_t nsOf(int64_t unixMs) { return std::max<int64_t>(unixMs, 0) * 1000000; }

}  // namespace

bool FoxgloveServer::hasRoom(const Client& client, size_t bytes) const {
  if (!client.socket) return true;
  int fd = g_socket_get_fd(client.socket);
  int queued = 0;
  if (ioctl(fd, SIOCOUTQ, &queued) != 0 || queued == 0) return true;
  // libsoup writes at once what the kernel takes and keeps the rest: a
  // message goes only while the kernel has room for all of it, so libsoup
  // never holds more than the one message that filled it.
  int buffer = 0;
  socklen_t length = sizeof buffer;
  getsockopt(fd, SOL_SOCKET, SO_SNDBUF, &buffer, &length);
  // SO_SNDBUF counts the kernel's bookkeeping too: about half is data.
  size_t room = std::min<size_t>(static_cast<size_t>(buffer) / 2, kMaxUnsent);
  return static_cast<size_t>(queued) + bytes <= room;
}

bool FoxgloveServer::watched(uint32_t channel) const {
  return std::any_of(clients_.begin(), clients_.end(),
                     [&](const auto& c) { return c->session.subscriptionTo(channel).has_value(); });
}

void FoxgloveServer::publish(uint32_t channel, std::string& frame, bool keyFrame, bool h264) {
  for (const auto& client : clients_) {
    auto subscription = client->session.subscriptionTo(channel);
    if (!subscription ||
        soup_websocket_connection_get_state(client->connection) != SOUP_WEBSOCKET_STATE_OPEN)
      continue;
    bool& decoding = client->decoding[channel];
    if (h264 && !decoding && !keyFrame) continue;  // a decoder starts at a key frame
    if (!hasRoom(*client, frame.size())) {
      ++client->dropped;
      ++dropped_;
      decoding = false;  // H.264 after a gap waits for the next key frame
      continue;
    }
    decoding = true;
    setSubscriptionId(frame, *subscription);
    soup_websocket_connection_send_binary(client->connection, frame.data(), frame.size());
    ++sent_;
  }
}

void FoxgloveServer::sendFrame(Feed& feed, GstSample* sample, int64_t utcNs) {
  auto it = feed.channels.find(FoxgloveTopic::Image);
  if (it == feed.channels.end()) return;
  GstBuffer* buffer = gst_sample_get_buffer(sample);
  gst::ScopedBufferMap map(buffer, GST_MAP_READ);
  if (!map) return;
  // A subscriber's first H.264 frame is an IDR, decided from the bitstream
  // (h264parse calls a scene cut's non-IDR I-frame a key frame too).
  bool key = !feed.h264 || gst::h264StartsDecoding(buffer, gst_sample_get_caps(sample));
  utcNs = stampOf(feed, GST_BUFFER_PTS(buffer), utcNs);
  std::string converted;
  std::string_view data = map.view();
  if (feed.h264) {
    // Foxglove decodes Annex B; the recording's H.264 is "avc", its SPS and
    // PPS in the caps' codec_data, read again only when the caps change.
    GstCaps* caps = gst_sample_get_caps(sample);
    if (caps != feed.annexBCaps) {
      gst_caps_replace(&feed.annexBCaps, caps);
      feed.annexB.reset();
      const GValue* record = gst_structure_get_value(gst_caps_get_structure(caps, 0), "codec_data");
      if (record && GST_VALUE_HOLDS_BUFFER(record)) {
        gst::ScopedBufferMap codec(gst_value_get_buffer(record), GST_MAP_READ);
        if (codec) feed.annexB = AnnexB::fromAvcC(codec.view());
      }
    }
    if (feed.annexB) {
      auto frame = feed.annexB->convert(data);
      if (!frame) return;
      converted = std::move(*frame);
      data = converted;
    }
  }
  std::string frame = messageDataHead(0, static_cast<uint64_t>(utcNs));
  frame += feed.h264 ? compressedVideoHead(utcNs, feed.camera.name, "h264", data.size())
                     : compressedImageHead(utcNs, feed.camera.name, "jpeg", data.size());
  frame += data;
  publish(it->second, frame, key, feed.h264);
}

void FoxgloveServer::publishBytes(const std::string& camera, FoxgloveTopic topic,
                                  const std::string& message, int64_t timeNs) {
  Feed* feed = feedNamed(camera);
  if (!feed) return;
  auto it = feed->channels.find(topic);
  if (it == feed->channels.end()) return;
  std::string frame = messageDataHead(0, static_cast<uint64_t>(timeNs)) + message;
  publish(it->second, frame);
}

void FoxgloveServer::publishJson(const std::string& camera, FoxgloveTopic topic,
                                 const nlohmann::json& message, int64_t unixMs) {
  publishBytes(camera, topic,
               message.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace),
               nsOf(unixMs));
}

void FoxgloveServer::telemetry(const std::string& camera, const nlohmann::json& line,
                               int64_t unixMs) {
  publishJson(camera, FoxgloveTopic::Telemetry, line, unixMs);
}

int64_t FoxgloveServer::stampOf(Feed& feed, uint64_t pts, int64_t firstNs) {
  constexpr size_t kFramesKept = 64;  // seconds of frames: the detector's lag and more
  if (pts == GST_CLOCK_TIME_NONE) return firstNs;
  auto [it, added] = feed.stamps.emplace(pts, firstNs);
  if (added && feed.stamps.size() > kFramesKept) feed.stamps.erase(feed.stamps.begin());
  return it->second;
}

void FoxgloveServer::detections(const std::string& camera, const nlohmann::json& line,
                                int64_t unixMs, uint64_t framePts) {
  Feed* feed = feedNamed(camera);
  if (!feed) return;
  // Built only for a client that shows them, not for every frame detected.
  if (!watched(feed->channels.at(FoxgloveTopic::Tags))) return;
  int64_t ns = stampOf(*feed, framePts, nsOf(unixMs));
  publishBytes(camera, FoxgloveTopic::Tags, imageAnnotationsOf(line, ns), ns);
}

void FoxgloveServer::log(const std::string& camera, const std::string& message, int64_t unixMs) {
  publishJson(camera, FoxgloveTopic::Log, foxgloveLog(camera, message, nsOf(unixMs)), unixMs);
}

void FoxgloveServer::pose(const std::string& camera, double x, double y, double z, int64_t unixMs) {
  publishBytes(camera, FoxgloveTopic::Pose, poseInFrameOf(x, y, z, nsOf(unixMs), "marvelmind"),
               nsOf(unixMs));
}

}  // namespace wircam::recorder
