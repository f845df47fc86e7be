// wirc-export: one camera's recordings over a time range as one file.
//   wirc-export --recordings DIR --camera NAME [--start ISO8601] [--end ISO8601]
//               --format mkv|mp4|mcap --out FILE|-
#include <getopt.h>
#include <gst/gst.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>

#include "export/exporter.h"
#include "export/fleet_fetch.h"

namespace {

using namespace wircam::recorder;

const char* kUsage =
    R"(Usage: wirc-export --recordings DIR --camera NAME [--start ISO8601] [--end ISO8601] --format mkv|mp4|mcap --out FILE|-
       wirc-export --fleet MQTT_URL --vehicle NAME [--camera camN] [--http-token T] [--start …] [--end …] --format … --out …

Writes one camera's recorded segments between two times as one file, the
frames untouched (JPEG stays JPEG, H.264 stays H.264), on one timeline from
0 at the first frame (an outage stays a gap), with the sidecars' telemetry
merged: as the "telemetry" text track (mkv, mp4) or on MCAP channels, and
re-based in FILE's .jsonl beside it.

  --recordings DIR   a wirc-recorder --out folder (its index.json; rebuilt
                     from the files when missing)
  --camera NAME      the stream, as in the file names: <device>-cam<N>
  --start, --end     UTC times, e.g. 2026-11-24T14:59:35Z or with an offset
                     (+01:00); without a zone, local time. Default: all
  --format           mkv | mp4 (H.264 recordings) | mcap (Foxglove, Lichtblick:
                     /NAME/image, /NAME/tags, /NAME/telemetry, /NAME/log)
  --fleet MQTT_URL   instead of --recordings: the segments of --vehicle from
                     every recorder announced on the fleet's broker (fleet.md),
                     fetched over HTTP(S), a dropped connection resumed;
                     --camera then says which of its cameras (default cam0)
  --vehicle NAME     with --fleet: the vehicle, by its serial or its name
  --http-token T     with --fleet: the recorders' --http-token
  --mqtt-cafile FILE with --fleet mqtts://: the broker's CA (PEM)
  --out FILE         the file to write (replaced); - streams it to stdout as
                     it is made (mkv without its index, mp4 fragmented; no
                     .jsonl), e.g. into ffplay, ssh or curl -T

On a terminal, progress is shown as it goes: frames, MB/s, time left.

Segments still being written are left out, and a broken one is skipped:
both are said; so is a segment that cannot be read (zeros, a cut or empty
file), which is given up within 2 s. Exit 0 when written, 1 when there is
nothing to export, it cannot be written or it was stopped (SIGINT, SIGTERM:
no output is left behind), 2 for a wrong command line.
)";

volatile std::sig_atomic_t stopRequested = 0;

// "1200 of 9000 frames (13%), 41.5 MB/s, 0:52 left".
std::string progressLine(uint64_t done, uint64_t total, uint64_t bytes,
                         std::chrono::steady_clock::time_point begun) {
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - begun).count();
  char line[160];
  int length =
      std::snprintf(line, sizeof line, "%llu of %llu frames (%d%%)",
                    static_cast<unsigned long long>(done), static_cast<unsigned long long>(total),
                    static_cast<int>(100 * std::min(done, total) / total));
  if (seconds > 0.5 && done > 0 && done < total) {
    auto left = static_cast<long>(seconds * static_cast<double>(total - done) / done);
    std::snprintf(line + length, sizeof line - length, ", %.1f MB/s, %ld:%02ld left",
                  static_cast<double>(bytes) / 1e6 / seconds, left / 60, left % 60);
  }
  return line;
}

// Where a fleet's segments wait for the export; gone with it, however it
// ends.
struct ScratchFolder {
  std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("wirc-export-fleet-" + std::to_string(getpid()));
  ~ScratchFolder() {
    std::error_code ignored;
    std::filesystem::remove_all(path, ignored);
  }
};

int usageError(const std::string& problem) {
  std::fprintf(stderr, "wirc-export: %s\n(wirc-export --help for the options)\n", problem.c_str());
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  gst_init(&argc, &argv);
  static const option options[] = {{"recordings", required_argument, nullptr, 'r'},
                                   {"camera", required_argument, nullptr, 'c'},
                                   {"start", required_argument, nullptr, 's'},
                                   {"end", required_argument, nullptr, 'e'},
                                   {"format", required_argument, nullptr, 'f'},
                                   {"out", required_argument, nullptr, 'o'},
                                   {"fleet", required_argument, nullptr, 'F'},
                                   {"vehicle", required_argument, nullptr, 'v'},
                                   {"http-token", required_argument, nullptr, 't'},
                                   {"mqtt-cafile", required_argument, nullptr, 'C'},
                                   {"help", no_argument, nullptr, 'h'},
                                   {nullptr, 0, nullptr, 0}};
  ExportRequest request;
  std::optional<FleetFetchRequest> fleet;
  std::string fleetUrl, caFile;
  bool formatGiven = false;
  int opt;
  while ((opt = getopt_long(argc, argv, "h", options, nullptr)) != -1) {
    switch (opt) {
      case 'r':
        request.recordings = optarg;
        break;
      case 'c':
        request.camera = optarg;
        break;
      case 's':
      case 'e': {
        auto time = parseIsoTime(optarg);
        if (!time)
          return usageError(std::string("--") + (opt == 's' ? "start" : "end") + " '" + optarg +
                            "' is not an ISO 8601 time like 2026-11-24T14:59:35Z");
        (opt == 's' ? request.start : request.end) = *time;
        break;
      }
      case 'f': {
        auto format = exportFormatOf(optarg);
        if (!format) return usageError(std::string("--format '") + optarg + "': mkv, mp4 or mcap");
        request.format = *format;
        formatGiven = true;
        break;
      }
      case 'o':
        request.out = optarg;
        break;
      case 'F':
        fleetUrl = optarg;
        break;
      case 'v':
        if (!fleet) fleet.emplace();
        fleet->vehicle = optarg;
        break;
      case 't':
        if (!fleet) fleet.emplace();
        fleet->token = optarg;
        break;
      case 'C':
        caFile = optarg;
        break;
      case 'h':
        std::fputs(kUsage, stdout);
        return 0;
      default:
        return usageError("unknown option");
    }
  }
  if (optind < argc) return usageError(std::string("unexpected argument '") + argv[optind] + "'");
  if (!fleetUrl.empty()) {
    if (!fleet || fleet->vehicle.empty()) return usageError("--fleet needs --vehicle NAME");
    if (!request.recordings.empty())
      return usageError("--fleet and --recordings: the segments come from one or the other");
    auto broker = parseMqttUrl(fleetUrl);
    if (!broker) return usageError("--fleet: " + broker.error());
    fleet->broker = *broker;
    if (!caFile.empty()) fleet->broker.caFile = caFile;
    if (!request.camera.empty()) fleet->camera = request.camera;
  } else if (fleet) {
    return usageError("--vehicle and --http-token go with --fleet MQTT_URL");
  } else {
    if (request.recordings.empty()) return usageError("--recordings DIR (or --fleet) is needed");
    if (request.camera.empty()) return usageError("--camera NAME is needed");
  }
  if (!formatGiven) return usageError("--format mkv|mp4|mcap is needed");
  if (request.out.empty()) return usageError("--out FILE is needed");
  if (request.start && request.end && *request.end < *request.start)
    return usageError("--end is before --start");

  // SIGINT and SIGTERM stop the export within 50 frames; the export then
  // removes what it had written, so no partial file is left.
  struct sigaction stop = {};
  stop.sa_handler = [](int) { stopRequested = 1; };
  sigaction(SIGINT, &stop, nullptr);
  sigaction(SIGTERM, &stop, nullptr);
  // A fleet's segments first, into a folder of their own for the export.
  std::optional<ScratchFolder> gathered;
  if (fleet) {
    gathered.emplace();
    fleet->folder = gathered->path;
    fleet->start = request.start;
    fleet->end = request.end;
    auto fetched = fetchFromFleet(*fleet, [](const std::string& line) {
      std::fprintf(stderr, "wirc-export: %s\n", line.c_str());
      return !stopRequested;
    });
    if (!fetched) {
      std::fprintf(stderr, "wirc-export: %s\n", fetched.error().c_str());
      return 1;
    }
    for (const auto& note : fetched->notes) std::fprintf(stderr, "wirc-export: %s\n", note.c_str());
    std::fprintf(stderr,
                 "wirc-export: %zu segments (%.1f MB) from %zu recorders (%zu announced, %zu "
                 "answered)\n",
                 fetched->segments, static_cast<double>(fetched->bytes) / 1e6, fetched->holders,
                 fetched->announced, fetched->asked);
    request.recordings = gathered->path;
    request.camera = fetched->camera;
    request.overlapping = true;
  }

  bool toStdout = request.out == "-";
  if (toStdout) {
    if (isatty(STDOUT_FILENO)) return usageError("--out - would write the file to the terminal");
    request.stream = STDOUT_FILENO;
  }
  bool terminal = isatty(STDERR_FILENO);
  auto begun = std::chrono::steady_clock::now();
  auto report = exportRange(request, [&](uint64_t done, uint64_t total, uint64_t bytes) {
    if (stopRequested) return false;
    if (!terminal || total == 0) return true;
    std::fprintf(stderr, "\rwirc-export: %s\x1b[K",
                 progressLine(done, total, bytes, begun).c_str());
    return true;
  });
  if (terminal) std::fputc('\n', stderr);
  if (!report) {
    std::fprintf(stderr, "wirc-export: %s\n", report.error().message.c_str());
    return 1;
  }
  for (const auto& note : report->notes) std::fprintf(stderr, "wirc-export: %s\n", note.c_str());
  // On stdout the file goes: the summary goes with the other messages.
  std::fprintf(toStdout ? stderr : stdout,
               "wirc-export: %s: %llu frames from %llu segments, %llu telemetry lines, %s to %s\n",
               request.out.c_str(), static_cast<unsigned long long>(report->frames),
               static_cast<unsigned long long>(report->segments),
               static_cast<unsigned long long>(report->lines),
               isoTimeOf(report->firstUtcNs).c_str(), isoTimeOf(report->lastUtcNs).c_str());
  return 0;
}
