#include "app/pipeline_planner.h"

#include <cctype>
#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <tuple>

#include "telemetry/telemetry_track_flags.h"

namespace wircam::recorder {

namespace {

// A file name part made of safe characters only.
std::string fileSafe(std::string text) {
  for (char& c : text)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '.') c = '_';
  return text;
}

MuxerSpec muxerOf(Container container) {
  return container == Container::kMp4 ? mp4Muxer() : matroskaMuxer();
}

// What the frames pass through on their way to the file, ending in the
// element named `tail`.
std::string encoder(const RecorderOptions& options, const std::string& head,
                    const std::string& tail) {
  if (options.codec == Codec::kJpeg) return "";
  // zerolatency: no B-frames and no look-ahead, so the live recording does
  // not lag. The recorder asks for a key frame at each cut and every 0.5 s
  // (SegmentWriter); key-int-max is only a backstop. The muxers take H.264
  // as "avc" only, and the file is linked after the caps are settled. Main
  // profile: what browsers decode over WebRTC (Chromium and Safari offer
  // it), so the live view passes the recording's frames on as they are.
  return "tjpegdec name=" + head +
         " ! videoconvert ! x264enc speed-preset=veryfast tune=zerolatency bitrate=" +
         std::to_string(options.h264Kbps) +
         " key-int-max=60 ! h264parse ! capsfilter name=" + tail +
         " caps=\"video/x-h264,stream-format=avc,alignment=au,profile=main\" ";
}

// wirccontrol's properties for the vehicle the device's tags steer: the
// WiRC device itself, or the RCOIP receiver or BTEMP robot of control=.
std::string controlOf(const DeviceTarget& device) {
  if (!device.control)
    return (device.host.empty() ? "" : " host=" + device.host) +
           " port=" + std::to_string(device.port);
  const auto& c = *device.control;
  return " protocol=" + c.protocol + " host=" + c.host + " port=" + std::to_string(c.port);
}

// The element that joins the vehicle's Marvelmind positions to its frames.
std::string positionsOf(const PositionSource& source, const std::string& name) {
  return "marvelmindpositions name=" + name + " host=" + source.host +
         " port=" + std::to_string(source.port) + " beacons=" + source.beacons + " ";
}

// The files' text track. For Matroska, the element the frames' thread
// feeds (telemetry/text_outlet.h); for MP4, after an appsrc of
// its own, which never blocks the main loop: past 1 MB waiting it drops.
// Its track is named by a stream tag (in Matroska a placeholder, rewritten
// when the file is finished: telemetry_track_flags.h).
std::string telemetryTrack(const RecorderOptions& options, const StreamPlan& stream) {
  bool matroska = options.container == Container::kMatroska;
  std::string title(matroska ? kTelemetryTrackPlaceholder : kTelemetryTrackName);
  std::string tag = "taginject name=" + stream.telemetryTail + " tags=\"title=" + title + "\" ";
  if (matroska) return tag;
  return "appsrc name=" + stream.telemetrySource +
         " is-live=true format=time min-latency=0 max-latency=-1 max-bytes=1000000 "
         "leaky-type=downstream caps=\"text/x-raw,format=(string)utf8\" ! " +
         tag;
}

}  // namespace

PipelinePlan planPipeline(const RecorderOptions& options) {
  PipelinePlan plan;
  plan.transcoded = options.codec != Codec::kJpeg;
  // The live branch feeds the web server, RTSP and the discovery snapshots.
  bool live = options.http || options.rtsp || options.foxglove || options.mqttDiscovery;
  for (const auto& device : options.devices) {
    bool controlled = false;
    std::string host = device.host.empty() ? "" : " host=" + device.host;
    std::string port = " port=" + std::to_string(device.port);
    std::string login;  // what the login configures, when the user said
    if (options.periods) login += " periods=" + *options.periods;
    if (options.failsafe) login += " failsafe=" + *options.failsafe;
    for (int camera : device.cameras) {
      // Each stream is a pipeline of its own (named after the stream): its
      // elements' names need not differ from another's, and a camera's
      // plan does not change with its place in the config (a reload
      // compares plans).
      StreamPlan stream;
      std::string& d = stream.description;
      stream.device = fileSafe(device.label);
      stream.host = device.host;
      stream.port = device.port;
      stream.camera = camera;
      stream.name = stream.device + "-cam" + std::to_string(camera);
      stream.source = "src";
      stream.muxer = muxerOf(options.container);
      stream.muxer.text = options.telemetryTrack;
      if (options.telemetryTrack) {
        if (options.container == Container::kMp4) stream.telemetrySource = "tel";
        stream.telemetryTail = "teltag";
      }
      if (!options.detectFamily.empty()) stream.detector = "det";
      if (!options.detectFamily.empty() && *device.follow && !controlled) {
        stream.controller = "ctl";
        controlled = true;  // one controller per vehicle: the first camera's
      }
      if (live) stream.liveSink = "live";
      if (device.positions) stream.positions = "pos";
      bool branches = !stream.detector.empty() || live;
      const std::string tee = "t";
      // wait-for-device: a recorder started before its vehicle waits for it.
      d += "wircsrc name=" + stream.source + host + port + login +
           " camera=" + std::to_string(camera) + " wait-for-device=true ";
      if (device.positions) d += "! " + positionsOf(*device.positions, stream.positions);
      if (branches) d += "! tee name=" + tee + " ";
      // A slow disk must hold up neither the source nor the other
      // branches, nor any other camera: the muxer hands its bytes to the
      // filesystem's writer, within the camera's bound in bytes
      // (camera/disk_writer.h), past which its frames are dropped. The
      // text track's lines go in on the same thread, each given its turn
      // in the muxer (telemetry/collect_pads_turns.h): a camera is one thread.
      // --record-queue 0: on the source's thread, whatever the disk does.
      std::string toFile = branches ? tee + ". ! " : "! ";
      stream.recordBound = options.recordQueueBytes;
      if (plan.transcoded) {
        stream.videoTail = "enc";
        stream.planPoint = "recdec";
        d += toFile + encoder(options, stream.planPoint, stream.videoTail);
      } else {
        stream.videoTail = branches ? tee : device.positions ? stream.positions : stream.source;
      }
      if (options.telemetryTrack) d += telemetryTrack(options, stream);
      if (!stream.detector.empty()) {
        // Detection must never hold the recording back: its queue drops.
        d += tee +
             ". ! queue leaky=downstream max-size-buffers=2 ! tjpegdec ! apriltagdetect name=" +
             stream.detector + " quad-decimate=1 family=" + options.detectFamily;
        if (!stream.controller.empty())
          d +=
              " ! wirccontrol name=" + stream.controller + controlOf(device) + options.followTuning;
        d += " ! fakesink sync=false async=false ";
      }
      if (!stream.liveSink.empty()) {
        d += tee +
             ". ! queue leaky=downstream max-size-buffers=2 ! appsink name=" + stream.liveSink +
             " sync=false async=false max-buffers=2 drop=true ";
      }
      plan.streams.push_back(std::move(stream));
    }
  }
  return plan;
}

std::optional<std::string> sameNamedStreams(const PipelinePlan& plan) {
  std::set<std::string> names;
  for (const auto& stream : plan.streams)
    if (!names.insert(stream.name).second)
      return "two cameras would both be named " + stream.name +
             " (device names that differ only in characters a file name cannot hold, or a "
             "camera listed twice): rename one";
  return std::nullopt;
}

std::optional<std::string> cameraRecordedTwice(const RecorderOptions& options) {
  std::map<std::tuple<std::string, uint16_t, int>, std::string> recordedBy;
  for (const auto& device : options.devices) {
    if (device.host.empty()) continue;  // found by discovery: known only then
    for (int camera : device.cameras) {
      auto [first, added] =
          recordedBy.emplace(std::tuple(device.host, device.port, camera), device.label);
      if (!added)
        return "'" + first->second + "' and '" + device.label + "' both record camera " +
               std::to_string(camera) + " of " + device.host + ":" + std::to_string(device.port) +
               ": a device streams each camera to one receiver, so the two would take the "
               "stream from each other; record it once";
    }
  }
  return std::nullopt;
}

}  // namespace wircam::recorder
