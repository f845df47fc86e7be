// The option table: the recording's own rows here (devices and cameras,
// files, retention, detection and following), the servers' in
// server_options.cpp, the [device NAME] keys in device_keys.cpp.
#include "app/option_table.h"

#include "app/option_rows.h"
#include "app/option_values.h"

namespace wircam::recorder {

using namespace option_rows;

namespace {

// The recording's own options: devices and cameras, files, retention,
// detection and following.
std::vector<OptionSpec> recordingRows() {
  return {
      {.name = "device",
       .value = "HOST[:PORT][,control=URI]",
       .fallback = "discovery",
       .section = kDevices,
       .help = "a vehicle to record, port 1984 unless given; repeatable. Without any `--device` "
               "(and no config file) the device is found by discovery. `control=rcoip://H:P`, "
               "`btemp://H:P` or `wirc://H:P`: with `--follow`, steer that vehicle instead of the "
               "WiRC device whose camera is recorded ([cousins.md](cousins.md))",
       .apply = [](RecorderOptions& o, const char* value) -> OptionProblem {
         auto target = deviceTarget(value);
         if (!target) return target.error();
         o.devices.push_back(*target);
         return std::nullopt;
       },
       .example = "192.168.1.1:1985",
       .commandLineOnly = true},
      {.name = "config",
       .value = "FILE",
       .fallback = "",
       .section = kDevices,
       .help = "read options and devices from an INI file ([below](#the-config-file)); a reload "
               "(`SIGHUP`, `POST /api/config/reload`) reads it again",
       .commandLineOnly = true},
      {.name = "camera",
       .value = "N",
       .fallback = "0",
       .section = kDevices,
       .reloadable = true,
       .deviceKey = "cameras",
       .help = "a camera of each device to record, 0..255; repeatable",
       .apply = [](RecorderOptions& o, const char* value) -> OptionProblem {
         auto camera = wholeWithin(value, 0, 255);
         if (!camera) return "0..255";
         o.cameras.push_back(static_cast<int>(*camera));
         return std::nullopt;
       },
       .example = "1"},
      {.name = "periods",
       .value = "US,...",
       .fallback = "20000",
       .section = kDevices,
       .reloadable = true,
       .help = "servo periods the login sets (CCFG): 12 comma-separated µs values or one for "
               "all, 5000..20000, ch1/ch2, ch3/ch4 and ch5/ch6 equal",
       .apply = channels(&RecorderOptions::periods, true),
       .example = "10000"},
      {.name = "failsafe",
       .value = "US,...",
       .fallback = "1500",
       .section = kDevices,
       .reloadable = true,
       .help = "what each channel does when the link is lost (FCFG): 800..2200 µs, 0 = hold the "
               "last pulse, 65535 = no pulse",
       .apply = channels(&RecorderOptions::failsafe, false),
       .example = "1000"},

      {.name = "out",
       .value = "DIR",
       .fallback = "",
       .section = kFiles,
       .help = "where the files go (created if missing)",
       .apply = text(&RecorderOptions::outDir),
       .example = "elsewhere"},
      {.name = "segment",
       .value = "S",
       .fallback = "60",
       .section = kFiles,
       .reloadable = true,
       .help = "seconds per segment, 1..86400 (a day; fractions too: `1.5`)",
       .apply = [](RecorderOptions& o, const char* value) -> OptionProblem {
         auto s = number(value);
         // (A length too long for nanoseconds in 64 bits reached a cast that is
         // undefined; a segment past a day is more likely a slip than a wish.)
         if (!s || *s < 1 || *s > 86400) return "seconds 1..86400";
         o.segmentSeconds = *s;
         return std::nullopt;
       },
       .example = "30"},
      {.name = "segment-size",
       .value = "SIZE",
       .fallback = "none",
       .section = kFiles,
       .reloadable = true,
       .help = "also end a segment at SIZE bytes (at least `100K`; `K`, `M`, `G`, `T` are powers "
               "of 1000)",
       .apply = [](RecorderOptions& o, const char* value) -> OptionProblem {
         auto bytes = byteSize(value);
         if (!bytes || *bytes < 100000) return "a size of at least 100K, like 100M";
         o.segmentBytes = *bytes;
         return std::nullopt;
       },
       .example = "100M"},
      {.name = "format",
       .value = "mkv|mp4",
       .fallback = "mkv",
       .section = kFiles,
       .reloadable = true,
       .help = "container; `mp4` needs `--codec h264` (mp4mux cannot carry JPEG)",
       .apply = [](RecorderOptions& o, const char* value) -> OptionProblem {
         std::string format = value;
         if (format != "mkv" && format != "mp4") return "mkv or mp4";
         o.container = format == "mp4" ? Container::kMp4 : Container::kMatroska;
         return std::nullopt;
       },
       .example = "mp4",
       .needs = {"codec", "h264"}},
      {.name = "codec",
       .value = "jpeg|h264",
       .fallback = "jpeg",
       .section = kFiles,
       .help = "`jpeg`: the camera's frames as they arrive, untouched; `h264`: transcoded with "
               "`x264enc` (Main profile, veryfast, zero latency, a key frame every 0.5 s; needs "
               "gstreamer1.0-plugins-ugly); the live servers' feeds depend on it, so a change "
               "takes a restart",
       .apply = [](RecorderOptions& o, const char* value) -> OptionProblem {
         std::string codec = value;
         if (codec != "jpeg" && codec != "h264") return "jpeg or h264";
         o.codec = codec == "h264" ? Codec::kH264 : Codec::kJpeg;
         return std::nullopt;
       },
       .example = "h264"},
      {.name = "bitrate",
       .value = "KBPS",
       .fallback = "2000",
       .section = kFiles,
       .reloadable = true,
       .help = "H.264 bit rate, 50..100000",
       .apply = wholeNumber(&RecorderOptions::h264Kbps, 50, 100000, "kbit/s"),
       .example = "1500"},
      {.name = "telemetry-track",
       .value = "on|off",
       .fallback = "on",
       .section = kFiles,
       .reloadable = true,
       .help = "the telemetry also as the file's text track `telemetry` (on the camera's own "
               "thread; in MP4 the text has a thread of its own); `off` keeps it in the sidecar "
               "only, which spares each frame its turn with the text in the muxer",
       .apply = onOff(&RecorderOptions::telemetryTrack),
       .example = "off"},
      {.name = "record-queue",
       .value = "SIZE",
       .fallback = "8M",
       .section = kFiles,
       .reloadable = true,
       .help = "how much of a camera's video may wait for a slow disk (`100K`..`1G`); past "
               "it the newest frames are dropped from the file, counted in `/api/status` "
               "(`recording_dropped`), `/metrics` and the log, while the live view, detection "
               "and following go on. One thread writes the files of every camera on a "
               "filesystem. `0`: each camera writes its files on its own thread, so a disk that "
               "stalls then stalls the camera's source and branches too",
       .apply = [](RecorderOptions& o, const char* value) -> OptionProblem {
         auto bytes = byteSize(value);
         if (!bytes || (*bytes != 0 && (*bytes < 100'000 || *bytes > 1'000'000'000)))
           return "0, or a size of 100K..1G, like 8M";
         o.recordQueueBytes = *bytes;
         return std::nullopt;
       },
       .example = "16M"},
      {.name = "duration",
       .value = "S",
       .fallback = "none",
       .section = kFiles,
       .help = "stop after S seconds",
       .apply = [](RecorderOptions& o, const char* value) -> OptionProblem {
         auto s = number(value);
         if (!s || *s <= 0) return "seconds > 0";
         o.duration = *s;
         return std::nullopt;
       },
       .example = "90"},
      {.name = "status",
       .value = "S",
       .fallback = "1",
       .section = kFiles,
       .help = "seconds between status lines",
       .apply = [](RecorderOptions& o, const char* value) -> OptionProblem {
         auto s = number(value);
         if (!s || *s <= 0) return "seconds > 0";
         o.statusSeconds = *s;
         return std::nullopt;
       },
       .example = "5"},
      {.name = "stall-timeout",
       .value = "S",
       .fallback = "5",
       .section = kFiles,
       .reloadable = true,
       .help = "a camera logged in but without a frame for S seconds (0.5..3600) is `no-video`: "
               "its file is closed and its pipeline started again, with backoff",
       .apply = seconds(&RecorderOptions::stallSeconds, 0.5, 3600),
       .example = "2.5"},

      {.name = "max-bytes",
       .value = "SIZE",
       .fallback = "none",
       .section = kRetention,
       .reloadable = true,
       .help = "keep the recordings under SIZE (e.g. `500M`, `20G`) by deleting the oldest "
               "finished segments",
       .apply = size(&RecorderOptions::maxBytes),
       .example = "20G"},
      {.name = "min-free",
       .value = "SIZE",
       .fallback = "none",
       .section = kRetention,
       .reloadable = true,
       .help = "delete the oldest finished segments while the disk has less than SIZE free",
       .apply = size(&RecorderOptions::minFree),
       .example = "1G"},
      {.name = "max-age",
       .value = "DURATION",
       .fallback = "none",
       .section = kRetention,
       .reloadable = true,
       .help = "delete finished segments older than DURATION (`7d`, `12h`, `30m`, `90s`; by "
               "their last write), looked at on start-up, at every closed segment and every "
               "minute",
       .apply = duration(&RecorderOptions::maxAge),
       .example = "7d"},
      {.name = "keep-events",
       .value = "DURATION",
       .fallback = "none",
       .section = kRetention,
       .reloadable = true,
       .help = "keep the segments whose sidecar shows a tag seen or a command off neutral this "
               "long instead of `--max-age` (longer)",
       .apply = duration(&RecorderOptions::keepEvents),
       .example = "30d",
       .needs = {"max-age", "7d"}},

      {.name = "detect",
       .value = "FAMILY",
       .fallback = "none",
       .section = kDetection,
       .reloadable = true,
       .help = "find AprilTags of this family (e.g. `tag36h11`; a misspelt one is refused with "
               "the list); detections go to the telemetry",
       .apply = text(&RecorderOptions::detectFamily),
       .example = "tag25h9"},
      {.name = "follow",
       .value = nullptr,
       .fallback = "off",
       .section = kDetection,
       .reloadable = true,
       .deviceKey = "follow",
       .help = "steer the vehicle after the largest tag (needs `--detect`)",
       .apply = [](RecorderOptions& o, const char* value) -> OptionProblem {
         auto on = trueOrFalse(value);
         if (!on) return "true or false";
         o.follow = *on;
         return std::nullopt;
       },
       .example = "true",
       .needs = {"detect", "tag36h11"}},
      {.name = "follow-tuning",
       .value = "K=V[,K=V...]",
       .fallback = "wirccontrol's",
       .section = kDetection,
       .reloadable = true,
       .help = "the follower's gains and limits: `steering-kp`, `steering-ki`, `steering-kd`, "
               "`throttle-kp`, `throttle-ki`, `throttle-kd` (0..100), `target-distance` "
               "(0.05..100 m), `max-throttle` (0..1); see [replay.md](replay.md)",
       .apply = [](RecorderOptions& o, const char* value) -> OptionProblem {
         auto tuning = followTuning(value);
         if (!tuning) return tuning.error();
         o.followTuning = *tuning;
         return std::nullopt;
       },
       .example = "steering-kp=2,max-throttle=0.5",
       .needs = {"detect", "tag36h11", "follow", "true"}},
      {.name = "marvelmind",
       .value = "HOST[:PORT]",
       .fallback = "none",
       .section = kDetection,
       .reloadable = true,
       .deviceKey = "marvelmind",
       .help = "a Marvelmind dashboard (port 49200) to ask where the vehicle is; needs "
               "`--beacon` ([marvelmind.md](marvelmind.md))",
       .apply = optionalText(&RecorderOptions::marvelmind),
       .example = "192.168.1.50:49201",
       .needs = {"beacon", "5"}},
      {.name = "beacon",
       .value = "ADDR[,ADDR]",
       .fallback = "none",
       .section = kDetection,
       .reloadable = true,
       .deviceKey = "beacon",
       .help = "the vehicle's mobile beacon address(es), 1..254: its positions go to the "
               "telemetry, `/api/status` and the live view's map",
       .apply = optionalText(&RecorderOptions::beacons),
       .example = "5,6",
       .needs = {"marvelmind", "192.168.1.50"}},
  };
}

}  // namespace

const std::vector<OptionSpec>& optionTable() {
  static const std::vector<OptionSpec> table = [] {
    auto rows = recordingRows();
    auto servers = serverOptionRows();
    rows.insert(rows.end(), servers.begin(), servers.end());
    return rows;
  }();
  return table;
}

const OptionSpec* findOption(const std::string& name) {
  for (const auto& spec : optionTable())
    if (name == spec.name) return &spec;
  return nullptr;
}

const std::vector<DeviceKeySpec>& deviceKeyTable() {
  static const std::vector<DeviceKeySpec> table = deviceKeyRows();
  return table;
}

const std::vector<const char*>& optionSections() {
  static const std::vector<const char*> sections = {kDevices, kFiles,    kRetention, kDetection,
                                                    kWeb,     kFoxglove, kFleet,     kOther};
  return sections;
}

}  // namespace wircam::recorder
