// Export throughput and memory: one recording made for the run
//   wirc-sim --frames DIR (720p JPEGs) → wirc-recorder --segment 5
// and then all of it joined into one file, three ways, side by side:
//   wirc-export --format mkv, wirc-export --format mcap, and the stock way,
//   ffmpeg -f concat -c copy of the same segments; then the same range as
//   the recorder streams it over HTTP (GET /api/export) to curl, with the
//   time to its first byte.
// MB/s is the segments' bytes over the wall time (the median of 3 runs);
// peak memory comes from wait4().
// Usage: bench_export [SECONDS] [FPS]   (default 20 s at 60 fps)
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "bench_arguments.h"
#include "child_process.h"
#include "synthetic_jpeg.h"

namespace {

namespace fs = std::filesystem;
using wircam::bench::spawn;
using wircam::bench::waitForUsage;

struct Run {
  double seconds = 0;
  long maxRssKb = 0;
};

// The median of three runs of `command` (by time), and its peak memory;
// nothing if a run fails.
std::optional<Run> measure(const std::string& command) {
  std::vector<Run> runs;
  for (int i = 0; i < 3; ++i) {
    auto start = std::chrono::steady_clock::now();
    auto usage = waitForUsage(spawn(command));
    if (usage.exitCode != 0) {
      std::fprintf(stderr, "bench_export: exit %d from %s\n", usage.exitCode, command.c_str());
      return std::nullopt;
    }
    runs.push_back({std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
                    usage.maxRssKb});
  }
  std::sort(runs.begin(), runs.end(), [](auto& a, auto& b) { return a.seconds < b.seconds; });
  return runs[1];
}

}  // namespace

int main(int argc, char** argv) {
  auto arguments = wircam::bench::positiveArguments(
      argc, argv, {20, 60}, "usage: bench_export [SECONDS [FPS]]   (default 20 s at 60 fps)");
  if (!arguments) return 2;
  double seconds = (*arguments)[0];
  int fps = static_cast<int>((*arguments)[1]);
  fs::path bin = fs::canonical("/proc/self/exe").parent_path();
  fs::path work = fs::temp_directory_path() / ("wircam-bench-export-" + std::to_string(getpid()));
  fs::create_directories(work / "frames");
  for (int i = 0; i < 30; ++i) {
    auto jpeg = wircam::bench::syntheticJpeg(1280, 720, i, 85);
    std::ofstream(work / "frames" / (std::to_string(100 + i) + ".jpg"), std::ios::binary)
        .write(reinterpret_cast<const char*>(jpeg.data()),
               static_cast<std::streamsize>(jpeg.size()));
  }

  // The recording.
  int port = 10000 + getpid() % 20000;  // below the ephemeral ports (32768 and up)
  pid_t sim = spawn((bin / "wirc-sim").string() + " --port " + std::to_string(port) + " --fps " +
                    std::to_string(fps) + " --frames " + (work / "frames").string() +
                    " --duration " + std::to_string(seconds + 3));
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  pid_t recorder = spawn(
      (bin / "wirc-recorder").string() + " --device 127.0.0.1:" + std::to_string(port) + " --out " +
      (work / "rec").string() + " --segment 5 --duration " + std::to_string(seconds));
  auto longer = std::chrono::seconds(static_cast<long>(seconds) + 30);
  waitForUsage(recorder, longer);
  waitForUsage(sim, longer);

  auto index = nlohmann::json::parse(std::ifstream(work / "rec" / "index.json"), nullptr, false);
  if (!index.is_object() || index["segments"].empty()) {
    std::fprintf(stderr, "bench_export: the recording failed (no segments in %s)\n",
                 (work / "rec").c_str());
    return 1;
  }
  std::string camera = index["segments"][0]["camera"];
  uint64_t bytes = 0, frames = 0;
  std::ofstream list(work / "concat.txt");
  for (const auto& segment : index["segments"]) {
    bytes += segment["bytes"].get<uint64_t>();
    frames += segment["frames"].get<uint64_t>();
    list << "file '" << (work / "rec" / segment["file"].get<std::string>()).string() << "'\n";
  }
  list.close();
  double megabytes = static_cast<double>(bytes) / 1e6;
  std::printf("recording: %zu segments, %llu frames of 1280x720 JPEG, %.1f MB\n",
              index["segments"].size(), static_cast<unsigned long long>(frames), megabytes);

  std::string exporter = (bin / "wirc-export").string() + " --recordings " +
                         (work / "rec").string() + " --camera " + camera;
  struct Way {
    const char* name;
    std::string command;
    fs::path out;
  };
  std::vector<Way> ways = {
      {"ffmpeg -f concat -c copy (mkv)",
       "ffmpeg -v error -y -f concat -safe 0 -i " + (work / "concat.txt").string() + " -c copy " +
           (work / "ffmpeg.mkv").string(),
       work / "ffmpeg.mkv"},
      {"wirc-export --format mkv",
       exporter + " --format mkv --out " + (work / "export.mkv").string(), work / "export.mkv"},
      {"wirc-export --format mcap",
       exporter + " --format mcap --out " + (work / "export.mcap").string(), work / "export.mcap"},
  };
  std::printf("%-32s | %8s | %8s | %8s | %15s | %s\n", "way", "MB/s", "seconds", "peak MB",
              "× ffmpeg's MB/s", "size × ffmpeg's mkv");
  double stock = 0, stockBytes = 0;
  for (const auto& way : ways) {
    auto run = measure(way.command);
    if (!run) return 1;
    double rate = megabytes / run->seconds;
    auto size = static_cast<double>(fs::file_size(way.out));
    if (stock == 0) stock = rate, stockBytes = size;
    std::printf("%-32s | %8.1f | %8.2f | %8.1f | %15.2f | %.3f\n", way.name, rate, run->seconds,
                static_cast<double>(run->maxRssKb) / 1024, rate / stock, size / stockBytes);
  }

  // The same range streamed by the recorder (GET /api/export, mkv) to
  // curl: how soon its first byte comes, its speed, and the recorder's
  // peak memory (its whole life, idle included).
  int httpPort = port + 1;
  pid_t server =
      spawn((bin / "wirc-recorder").string() + " --device 127.0.0.1:" + std::to_string(port) +
                " --out " + (work / "rec").string() +
                " --http 127.0.0.1:" + std::to_string(httpPort) + " --duration 900",
            "/dev/null", (work / "server.log").string());
  std::string url =
      "http://127.0.0.1:" + std::to_string(httpPort) + "/api/export?format=mkv&camera=" + camera;
  std::string curl = "curl -sf -o " + (work / "http.mkv").string() +
                     " -w '%{time_starttransfer} %{time_total}' '" + url + "'";
  std::vector<std::pair<double, double>> streamed;  // (first byte, all) seconds
  for (int attempt = 0; attempt < 100 && streamed.size() < 3; ++attempt) {
    FILE* out = popen(curl.c_str(), "r");
    double first = 0, all = 0;
    bool read = out && std::fscanf(out, "%lf %lf", &first, &all) == 2;
    bool ok = out && pclose(out) == 0 && read;
    if (ok)
      streamed.push_back({first, all});
    else
      std::this_thread::sleep_for(std::chrono::milliseconds(100));  // not listening yet
  }
  kill(-server, SIGINT);  // (stopGroup would reap it before its usage is read)
  auto serverUsage = waitForUsage(server);
  if (streamed.size() < 3) {
    std::fprintf(stderr, "bench_export: GET %s failed (log: %s)\n", url.c_str(),
                 (work / "server.log").c_str());
    return 1;
  }
  std::sort(streamed.begin(), streamed.end(), [](auto& a, auto& b) { return a.second < b.second; });
  double rate = megabytes / streamed[1].second;
  std::printf("%-32s | %8.1f | %8.2f | %8.1f | %15.2f | %.3f\n", "GET /api/export (mkv, curl)",
              rate, streamed[1].second, static_cast<double>(serverUsage.maxRssKb) / 1024,
              rate / stock, static_cast<double>(fs::file_size(work / "http.mkv")) / stockBytes);
  std::printf(
      "GET /api/export: first byte after %.3f s (median of 3), the recorder's peak %.1f MB\n",
      streamed[1].first, static_cast<double>(serverUsage.maxRssKb) / 1024);
  fs::remove_all(work);
  return 0;
}
