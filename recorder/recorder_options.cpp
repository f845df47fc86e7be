#include "recorder_options.h"

#include <getopt.h>

#include <cstdlib>

namespace wircam::recorder {

const char* usage() {
  return R"(Usage: wirc-recorder --device HOST[:PORT] [--device ...] --out DIR [OPTIONS]

Records the cameras of one or more WiRC devices into segmented files, the
JPEG frames muxed as they arrive (no re-encoding), with a telemetry sidecar
(JSON lines) per segment. SIGINT or SIGTERM finishes every file and exits 0.

  --device HOST[:PORT]   a device to record (default port 1984); repeatable.
                         Without --device the device is found by discovery.
  --camera N             camera to record (default 0); repeatable
  --out DIR              where the files go (created if missing)
  --segment S            seconds per segment (default 60)
  --format mkv|mp4       container (default mkv: Matroska)
  --detect FAMILY        find AprilTags (e.g. tag36h11); detections go to telemetry
  --follow               steer the vehicle after the largest tag (needs --detect)
  --duration S           stop after S seconds
  --status S             seconds between status updates (default 1)
  --max-bytes SIZE       keep the recordings under SIZE (e.g. 500M, 20G) by
                         deleting the oldest finished segments
  --min-free SIZE        delete the oldest finished segments while the disk
                         has less than SIZE free
  -h, --help             this text

Files: DIR/<device>-cam<N>-<start time>-<segment>.<mkv|mp4> and, beside each,
<same name>.jsonl with one JSON object per event: {"pts": running time in ns,
"type": "psd"|"detections"|"control"|"stats", ...}.
)";
}

namespace {

// "500M", "20G", "1048576": bytes.
std::optional<uint64_t> size(const char* text) {
  char* end = nullptr;
  double value = std::strtod(text, &end);
  if (end == text || value < 0) return std::nullopt;
  std::string unit = end;
  double scale = unit.empty()  ? 1
                 : unit == "K" ? 1e3
                 : unit == "M" ? 1e6
                 : unit == "G" ? 1e9
                 : unit == "T" ? 1e12
                               : 0;
  if (scale == 0) return std::nullopt;
  return static_cast<uint64_t>(value * scale);
}

std::optional<double> number(const char* text) {
  char* end = nullptr;
  double value = std::strtod(text, &end);
  if (end == text || *end != '\0') return std::nullopt;
  return value;
}

Expected<DeviceTarget, std::string> deviceTarget(const std::string& text) {
  DeviceTarget target;
  auto colon = text.rfind(':');
  target.host = text.substr(0, colon);
  if (colon != std::string::npos) {
    auto port = number(text.substr(colon + 1).c_str());
    if (!port || *port < 1 || *port > 65535) return unexpected("bad port in --device " + text);
    target.port = static_cast<uint16_t>(*port);
  }
  if (target.host.empty())
    return unexpected("--device needs a host, as in 192.168.1.1 or 127.0.0.1:1984");
  target.label = target.host + (target.port == 1984 ? "" : "-" + std::to_string(target.port));
  return target;
}

}  // namespace

Expected<RecorderOptions, std::string> parseOptions(int argc, char** argv) {
  enum {
    kDevice = 1000,
    kCamera,
    kOut,
    kSegment,
    kFormat,
    kDetect,
    kFollow,
    kDuration,
    kStatus,
    kMaxBytes,
    kMinFree
  };
  static const option options[] = {{"device", required_argument, nullptr, kDevice},
                                   {"camera", required_argument, nullptr, kCamera},
                                   {"out", required_argument, nullptr, kOut},
                                   {"segment", required_argument, nullptr, kSegment},
                                   {"format", required_argument, nullptr, kFormat},
                                   {"detect", required_argument, nullptr, kDetect},
                                   {"follow", no_argument, nullptr, kFollow},
                                   {"duration", required_argument, nullptr, kDuration},
                                   {"status", required_argument, nullptr, kStatus},
                                   {"max-bytes", required_argument, nullptr, kMaxBytes},
                                   {"min-free", required_argument, nullptr, kMinFree},
                                   {"help", no_argument, nullptr, 'h'},
                                   {nullptr, 0, nullptr, 0}};
  RecorderOptions o;
  bool outGiven = false;
  optind = 1;
  int opt;
  while ((opt = getopt_long(argc, argv, "h", options, nullptr)) != -1) {
    switch (opt) {
      case 'h':
        return unexpected(std::string("help"));
      case kDevice: {
        auto target = deviceTarget(optarg);
        if (!target) return unexpected(target.error());
        o.devices.push_back(*target);
        break;
      }
      case kCamera: {
        auto camera = number(optarg);
        if (!camera || *camera < 0 || *camera > 255)
          return unexpected(std::string("--camera wants 0..255"));
        o.cameras.push_back(static_cast<int>(*camera));
        break;
      }
      case kOut:
        o.outDir = optarg;
        outGiven = true;
        break;
      case kSegment: {
        auto seconds = number(optarg);
        if (!seconds || *seconds < 1)
          return unexpected(std::string("--segment wants seconds >= 1"));
        o.segmentSeconds = *seconds;
        break;
      }
      case kFormat:
        if (std::string(optarg) == "mkv")
          o.container = Container::Matroska;
        else if (std::string(optarg) == "mp4")
          o.container = Container::Mp4;
        else
          return unexpected(std::string("--format is mkv or mp4"));
        break;
      case kDetect:
        o.detectFamily = optarg;
        break;
      case kFollow:
        o.follow = true;
        break;
      case kDuration: {
        auto seconds = number(optarg);
        if (!seconds || *seconds <= 0)
          return unexpected(std::string("--duration wants seconds > 0"));
        o.duration = *seconds;
        break;
      }
      case kStatus: {
        auto seconds = number(optarg);
        if (!seconds || *seconds <= 0) return unexpected(std::string("--status wants seconds > 0"));
        o.statusSeconds = *seconds;
        break;
      }
      case kMaxBytes:
      case kMinFree: {
        auto bytes = size(optarg);
        if (!bytes)
          return unexpected(std::string("a size is a number with K, M, G or T, like 500M"));
        (opt == kMaxBytes ? o.maxBytes : o.minFree) = *bytes;
        break;
      }
      default:
        return unexpected(std::string("unknown option"));
    }
  }
  if (optind < argc) return unexpected(std::string("unexpected argument '") + argv[optind] + "'");
  if (!outGiven) return unexpected(std::string("--out DIR is needed"));
  if (o.follow && o.detectFamily.empty())
    return unexpected(std::string("--follow needs --detect FAMILY"));
  if (o.devices.empty()) o.devices.push_back({"", 1984, "discovered"});
  if (o.cameras.empty()) o.cameras.push_back(0);
  return o;
}

}  // namespace wircam::recorder
