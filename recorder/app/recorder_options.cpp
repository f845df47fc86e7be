#include "app/recorder_options.h"

#include <getopt.h>
#include <glib.h>

#include <memory>

#include "app/option_values.h"
#include "fleet/mqtt_url.h"
#include "marvelmind/position_client.h"
#include "record/retention.h"
#include "wirc/channel_list.h"

namespace wircam::recorder {

const char* extensionOf(Container container) {
  return container == Container::kMp4 ? ".mp4" : ".mkv";
}

namespace {

// Applies one option given by its long name (from the command line or the
// config file's [recorder] group).
std::optional<std::string> applyOption(RecorderOptions& o, const std::string& name,
                                       const char* value);

Expected<std::vector<DeviceTarget>, std::string> loadConfig(const char* path, RecorderOptions& o) {
  std::unique_ptr<GKeyFile, decltype(&g_key_file_free)> file(g_key_file_new(), g_key_file_free);
  GError* error = nullptr;
  if (!g_key_file_load_from_file(file.get(), path, G_KEY_FILE_NONE, &error)) {
    std::string message = std::string("cannot read --config ") + path + ": " + error->message;
    g_error_free(error);
    return unexpected(message);
  }
  std::vector<DeviceTarget> devices;
  gsize count = 0;
  std::unique_ptr<gchar*, decltype(&g_strfreev)> groups(g_key_file_get_groups(file.get(), &count),
                                                        g_strfreev);
  for (gsize g = 0; g < count; ++g) {
    std::string group = groups.get()[g];
    gsize keyCount = 0;
    std::unique_ptr<gchar*, decltype(&g_strfreev)> keys(
        g_key_file_get_keys(file.get(), group.c_str(), &keyCount, nullptr), g_strfreev);
    auto value = [&](const char* key) -> std::string {
      gchar* text = g_key_file_get_string(file.get(), group.c_str(), key, nullptr);
      std::string out = text ? text : "";
      g_free(text);
      return out;
    };
    if (group == "recorder") {
      for (gsize k = 0; k < keyCount; ++k) {
        std::string key = keys.get()[k];
        if (auto problem = applyOption(o, key, value(key.c_str()).c_str()))
          return unexpected(std::string(path) + " [recorder] " + key + ": " + *problem);
      }
    } else if (group.rfind("device ", 0) == 0) {
      DeviceTarget device;
      device.label = group.substr(7);
      for (gsize k = 0; k < keyCount; ++k) {
        std::string key = keys.get()[k];
        std::string text = value(key.c_str());
        auto where = std::string(path) + " [" + group + "] " + key;
        if (key == "host") {
          device.host = text;
        } else if (key == "port") {
          auto port = number(text.c_str());
          if (!port || *port < 1 || *port > 65535)
            return unexpected(where + ": a port is 1..65535");
          device.port = static_cast<uint16_t>(*port);
        } else if (key == "cameras") {
          gsize n = 0;
          std::unique_ptr<gint, decltype(&g_free)> list(
              g_key_file_get_integer_list(file.get(), group.c_str(), "cameras", &n, nullptr),
              g_free);
          if (!list) return unexpected(where + ": a list like 0;1");
          for (gsize i = 0; i < n; ++i) device.cameras.push_back(list.get()[i]);
        } else if (key == "follow") {
          device.follow = text == "true" || text == "1";
        } else if (key == "control") {
          auto control = parseControlTarget(text);
          if (!control) return unexpected(where + ": " + control.error());
          device.control = *control;
        } else if (key == "marvelmind") {
          device.marvelmind = text;
        } else if (key == "beacon") {
          device.beacons = text;
        } else {
          return unexpected(where +
                            ": unknown key (host, port, cameras, follow, control, marvelmind, "
                            "beacon)");
        }
      }
      if (device.host.empty()) return unexpected(std::string(path) + " [" + group + "] needs host");
      devices.push_back(std::move(device));
    } else {
      return unexpected(std::string(path) + ": unknown group [" + group +
                        "] ([recorder] or [device NAME])");
    }
  }
  return devices;
}

std::optional<std::string> applyOption(RecorderOptions& o, const std::string& name,
                                       const char* value) {
  if (name == "out") {
    o.outDir = value;
  } else if (name == "segment") {
    auto seconds = number(value);
    if (!seconds || *seconds < 1) return "seconds >= 1";
    o.segmentSeconds = *seconds;
  } else if (name == "segment-size") {
    auto bytes = byteSize(value);
    if (!bytes || *bytes < 100000) return "a size of at least 100K, like 100M";
    o.segmentBytes = *bytes;
  } else if (name == "format") {
    std::string format = value;
    if (format != "mkv" && format != "mp4") return "mkv or mp4";
    o.container = format == "mp4" ? Container::kMp4 : Container::kMatroska;
  } else if (name == "codec") {
    std::string codec = value;
    if (codec != "jpeg" && codec != "h264") return "jpeg or h264";
    o.codec = codec == "h264" ? Codec::kH264 : Codec::kJpeg;
  } else if (name == "telemetry-track") {
    std::string track = value;
    if (track != "on" && track != "off") return "on or off";
    o.telemetryTrack = track == "on";
  } else if (name == "bitrate") {
    auto kbps = number(value);
    if (!kbps || *kbps < 50 || *kbps > 100000) return "kbit/s, 50..100000";
    o.h264Kbps = static_cast<unsigned>(*kbps);
  } else if (name == "http" || name == "rtsp" || name == "foxglove") {
    auto address = parseServerAddress(value);
    if (!address) return "[HOST]:PORT, as in :8080 or 127.0.0.1:8080";
    (name == "http" ? o.http : name == "rtsp" ? o.rtsp : o.foxglove) = *address;
  } else if (name == "foxglove-max-clients") {
    auto clients = number(value);
    if (!clients || *clients < 1 || *clients > 64 || *clients != static_cast<int>(*clients))
      return "1..64";
    o.foxgloveMaxClients = static_cast<unsigned>(*clients);
  } else if (name == "http-cert" || name == "http-key") {
    (name == "http-cert" ? o.httpCert : o.httpKey) = value;
  } else if (name == "webrtc") {
    std::string on = value;
    if (on != "on" && on != "off") return "on or off";
    o.webrtc = on == "on";
  } else if (name == "webrtc-stun") {
    if (!g_str_has_prefix(value, "stun://") || !g_uri_is_valid(value, G_URI_FLAGS_NONE, nullptr))
      return "a STUN server as stun://HOST:PORT";
    o.webrtcStun = value;
  } else if (name == "webrtc-turn") {
    if ((!g_str_has_prefix(value, "turn://") && !g_str_has_prefix(value, "turns://")) ||
        !g_uri_is_valid(value, G_URI_FLAGS_HAS_PASSWORD, nullptr))
      return "a TURN server as turn://USER:PASSWORD@HOST:PORT (or turns://)";
    o.webrtcTurn = value;
  } else if (name == "webrtc-kbps") {
    auto kbps = number(value);
    if (!kbps || *kbps < 50 || *kbps > 20000) return "kbit/s, 50..20000";
    o.webrtcKbps = static_cast<unsigned>(*kbps);
  } else if (name == "http-token") {
    std::string token = value;
    if (token.size() < 16 || token.find_first_of(" ;,\"\\") != std::string::npos)
      return "at least 16 characters, no spaces, quotes, commas or semicolons (e.g. from "
             "openssl rand -hex 16)";
    o.httpToken = token;
  } else if (name == "http-idle-timeout") {
    auto seconds = number(value);
    if (!seconds || *seconds < 0.1 || *seconds > 3600) return "seconds, 0.1..3600";
    o.httpIdleSeconds = *seconds;
  } else if (name == "stall-timeout") {
    auto seconds = number(value);
    if (!seconds || *seconds < 0.5 || *seconds > 3600) return "seconds, 0.5..3600";
    o.stallSeconds = *seconds;
  } else if (name == "detect") {
    o.detectFamily = value;
  } else if (name == "follow") {
    o.follow = std::string(value) != "false" && std::string(value) != "0";
  } else if (name == "follow-tuning") {
    auto tuning = followTuning(value);
    if (!tuning) return tuning.error();
    o.followTuning = *tuning;
  } else if (name == "duration") {
    auto seconds = number(value);
    if (!seconds || *seconds <= 0) return "seconds > 0";
    o.duration = *seconds;
  } else if (name == "status") {
    auto seconds = number(value);
    if (!seconds || *seconds <= 0) return "seconds > 0";
    o.statusSeconds = *seconds;
  } else if (name == "max-bytes" || name == "min-free") {
    auto bytes = byteSize(value);
    if (!bytes) return "a size like 500M or 20G";
    (name == "max-bytes" ? o.maxBytes : o.minFree) = *bytes;
  } else if (name == "max-age" || name == "keep-events") {
    auto duration = parseDuration(value);
    if (!duration || duration->count() == 0) return "a duration like 7d, 12h, 30m or 90s";
    (name == "max-age" ? o.maxAge : o.keepEvents) = *duration;
  } else if (name == "periods" || name == "failsafe") {
    auto channels = wirc::parseChannelList(value);
    if (!channels) return channels.error();
    auto valid = name == "periods" ? wirc::validate(wirc::Ccfg{*channels})
                                   : wirc::validate(wirc::Fcfg{*channels});
    if (valid) return valid->message();
    (name == "periods" ? o.periods : o.failsafe) = value;
  } else if (name == "mqtt") {
    auto url = parseMqttUrl(value);
    if (!url) return url.error();
    o.mqtt = value;
  } else if (name == "mqtt-discovery") {
    // Alone (or =true in the config file): Home Assistant's own prefix.
    std::string prefix = value;
    if (prefix == "true") prefix = "homeassistant";
    if (prefix == "false") return std::nullopt;
    if (prefix.empty() || prefix.find_first_of("+# ") != std::string::npos ||
        prefix.front() == '/' || prefix.back() == '/')
      return "a topic prefix without + # or a leading or trailing /, like homeassistant";
    o.mqttDiscovery = prefix;
  } else if (name == "mqtt-snapshot-interval") {
    auto seconds = number(value);
    if (!seconds || *seconds < 0.5 || *seconds > 3600) return "seconds, 0.5..3600";
    o.mqttSnapshotSeconds = *seconds;
  } else if (name == "mqtt-cafile") {
    o.mqttCaFile = value;
  } else if (name == "mqtt-prefix") {
    std::string prefix = value;
    if (prefix.empty() || prefix.find_first_of("+#") != std::string::npos ||
        prefix.front() == '/' || prefix.back() == '/')
      return "a topic prefix without + # or a leading or trailing /, like wircam or lab/rovers";
    o.mqttPrefix = prefix;
  } else if (name == "mqtt-detections-rate") {
    auto rate = number(value);
    if (!rate || *rate < 0 || *rate > 1000) return "messages per second, 0..1000 (0: every frame)";
    o.mqttDetectionsRate = *rate;
  } else if (name == "on-segment-closed") {
    gchar** argv = nullptr;
    GError* error = nullptr;
    if (!g_shell_parse_argv(value, nullptr, &argv, &error)) {
      std::string problem = error->message;
      g_error_free(error);
      return "cannot split the command: " + problem;
    }
    o.onSegmentClosed.assign(argv, argv + g_strv_length(argv));
    g_strfreev(argv);
  } else if (name == "hook-timeout") {
    auto seconds = number(value);
    if (!seconds || *seconds < 1 || *seconds > 86400) return "seconds, 1..86400";
    o.hookTimeoutSeconds = *seconds;
  } else if (name == "hook-drain") {
    auto seconds = number(value);
    if (!seconds || *seconds < 0 || *seconds > 3600) return "seconds, 0..3600";
    o.hookDrainSeconds = *seconds;
  } else if (name == "marvelmind") {
    o.marvelmind = value;
  } else if (name == "beacon") {
    o.beacons = value;
  } else if (name == "camera") {
    auto camera = number(value);
    if (!camera || *camera < 0 || *camera > 255) return "0..255";
    o.cameras.push_back(static_cast<int>(*camera));
  } else {
    return "unknown option";
  }
  return std::nullopt;
}

}  // namespace

Expected<RecorderOptions, std::string> parseOptions(int argc, char** argv) {
  enum { kDevice = 1000, kConfig, kValue };
  // Every other long option is applied by applyOption() under its own name.
  static const option options[] = {{"device", required_argument, nullptr, kDevice},
                                   {"config", required_argument, nullptr, kConfig},
                                   {"camera", required_argument, nullptr, kValue},
                                   {"out", required_argument, nullptr, kValue},
                                   {"segment", required_argument, nullptr, kValue},
                                   {"segment-size", required_argument, nullptr, kValue},
                                   {"format", required_argument, nullptr, kValue},
                                   {"codec", required_argument, nullptr, kValue},
                                   {"bitrate", required_argument, nullptr, kValue},
                                   {"telemetry-track", required_argument, nullptr, kValue},
                                   {"http", required_argument, nullptr, kValue},
                                   {"rtsp", required_argument, nullptr, kValue},
                                   {"foxglove", required_argument, nullptr, kValue},
                                   {"foxglove-max-clients", required_argument, nullptr, kValue},
                                   {"http-idle-timeout", required_argument, nullptr, kValue},
                                   {"stall-timeout", required_argument, nullptr, kValue},
                                   {"http-token", required_argument, nullptr, kValue},
                                   {"http-cert", required_argument, nullptr, kValue},
                                   {"http-key", required_argument, nullptr, kValue},
                                   {"webrtc", required_argument, nullptr, kValue},
                                   {"webrtc-stun", required_argument, nullptr, kValue},
                                   {"webrtc-turn", required_argument, nullptr, kValue},
                                   {"webrtc-kbps", required_argument, nullptr, kValue},
                                   {"detect", required_argument, nullptr, kValue},
                                   {"follow", no_argument, nullptr, kValue},
                                   {"follow-tuning", required_argument, nullptr, kValue},
                                   {"duration", required_argument, nullptr, kValue},
                                   {"status", required_argument, nullptr, kValue},
                                   {"max-bytes", required_argument, nullptr, kValue},
                                   {"min-free", required_argument, nullptr, kValue},
                                   {"max-age", required_argument, nullptr, kValue},
                                   {"keep-events", required_argument, nullptr, kValue},
                                   {"periods", required_argument, nullptr, kValue},
                                   {"failsafe", required_argument, nullptr, kValue},
                                   {"marvelmind", required_argument, nullptr, kValue},
                                   {"mqtt", required_argument, nullptr, kValue},
                                   {"mqtt-prefix", required_argument, nullptr, kValue},
                                   {"mqtt-cafile", required_argument, nullptr, kValue},
                                   {"mqtt-discovery", optional_argument, nullptr, kValue},
                                   {"mqtt-snapshot-interval", required_argument, nullptr, kValue},
                                   {"mqtt-detections-rate", required_argument, nullptr, kValue},
                                   {"on-segment-closed", required_argument, nullptr, kValue},
                                   {"hook-timeout", required_argument, nullptr, kValue},
                                   {"hook-drain", required_argument, nullptr, kValue},
                                   {"beacon", required_argument, nullptr, kValue},
                                   {"help", no_argument, nullptr, 'h'},
                                   {nullptr, 0, nullptr, 0}};
  RecorderOptions o;
  o.outDir.clear();
  optind = 1;
  int opt, index = 0;
  while ((opt = getopt_long(argc, argv, "h", options, &index)) != -1) {
    switch (opt) {
      case 'h':
        return unexpected("help");
      case kDevice: {
        auto target = deviceTarget(optarg);
        if (!target) return unexpected(target.error());
        o.devices.push_back(*target);
        break;
      }
      case kConfig: {
        auto devices = loadConfig(optarg, o);
        if (!devices) return unexpected(devices.error());
        o.devices.insert(o.devices.end(), devices->begin(), devices->end());
        break;
      }
      case kValue: {
        std::string name = options[index].name;
        // "--mqtt-discovery [PREFIX]": the prefix may follow as a word of
        // its own (getopt takes an optional value only after "=").
        if (options[index].has_arg == optional_argument && !optarg && optind < argc &&
            argv[optind][0] != '-')
          optarg = argv[optind++];
        if (auto problem = applyOption(o, name, optarg ? optarg : "true"))
          return unexpected("--" + name + ": " + *problem);
        break;
      }
      default:
        return unexpected("unknown option");
    }
  }
  if (optind < argc) return unexpected(std::string("unexpected argument '") + argv[optind] + "'");
  if (o.outDir.empty()) return unexpected("--out DIR (or out= in the config) is needed");
  if (o.follow && o.detectFamily.empty()) return unexpected("--follow needs --detect FAMILY");
  if (o.mqttDiscovery && !o.mqtt)
    return unexpected("--mqtt-discovery publishes to the MQTT broker: it needs --mqtt URL");
  if (!o.mqttCaFile.empty() && (!o.mqtt || !parseMqttUrl(*o.mqtt)->tls))
    return unexpected("--mqtt-cafile is for a TLS broker: --mqtt mqtts://HOST[:PORT]");
  if (o.httpCert.empty() != o.httpKey.empty())
    return unexpected("--http-cert and --http-key go together: the certificate and its key");
  if (!o.httpCert.empty() && !o.http && !o.foxglove)
    return unexpected("--http-cert needs --http [HOST]:PORT (or --foxglove)");
  if (o.keepEvents.count() > 0 && o.keepEvents <= o.maxAge)
    return unexpected(
        "--keep-events keeps segments with events longer than --max-age: give "
        "--max-age and a longer --keep-events");
  if (!o.followTuning.empty() && !o.follow)
    return unexpected("--follow-tuning tunes the follower: it needs --follow");
  if (o.container == Container::kMp4 && o.codec == Codec::kJpeg)
    return unexpected(
        "--format mp4 needs --codec h264: GStreamer's mp4mux cannot carry the camera's JPEG "
        "frames as they are (use mkv to keep them untouched)");
  if (o.http && o.httpToken.empty() && !o.http->host.empty() && o.http->host != "127.0.0.1" &&
      o.http->host != "localhost")
    return unexpected("--http " + o.http->host + ":" + std::to_string(o.http->port) +
                      " would open the recorder beyond this machine without authentication: "
                      "give --http-token T (or leave HOST out for 127.0.0.1 only)");
  if (o.foxglove && o.httpToken.empty() && !o.foxglove->host.empty() &&
      o.foxglove->host != "127.0.0.1" && o.foxglove->host != "localhost")
    return unexpected("--foxglove " + o.foxglove->host + ":" + std::to_string(o.foxglove->port) +
                      " would open the recorder beyond this machine without authentication: "
                      "give --http-token T (or leave HOST out for 127.0.0.1 only)");
  if (o.devices.empty()) o.devices.push_back({"", 1984, "discovered"});
  if (o.cameras.empty()) o.cameras.push_back(0);
  for (auto& device : o.devices) {
    if (device.cameras.empty()) device.cameras = o.cameras;
    if (!device.follow) device.follow = o.follow;
    if (device.control && !*device.follow)
      return unexpected("device " + device.label +
                        " has control=, which steers only with follow (--follow or follow=true)");
    if (*device.follow && o.detectFamily.empty())
      return unexpected("device " + device.label + " follows, which needs detect=FAMILY");
    auto positions = positionSource(device.marvelmind ? device.marvelmind : o.marvelmind,
                                    device.beacons ? device.beacons : o.beacons);
    if (!positions) return unexpected("device " + device.label + ": " + positions.error());
    device.positions = *positions;
  }
  return o;
}

}  // namespace wircam::recorder
