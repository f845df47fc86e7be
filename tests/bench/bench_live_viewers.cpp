// 50 people watching one camera live, half of them on a link so slow that
// they read nothing: what it costs the recorder and whether the recording
// waits for them. Side by side, the stock GStreamer way to serve MJPEG to
// many viewers (multipartmux ! tcpserversink) with the same viewers, and
// the same viewers as Foxglove clients subscribed to the camera's image.
//   wirc-sim (the follow scene) → wirc-recorder --http → N viewers
//   wirc-sim → wirc-recorder --foxglove → N Foxglove subscribers
//   wirc-sim → gst-launch-1.0 wircsrc ! multipartmux ! tcpserversink → N viewers
// Each server's memory (VmRSS half-way and at the end, to show whether it
// keeps growing; VmHWM, its peak) and CPU come from /proc; the frames
// each fast viewer got are counted at the viewer, the recorded frames read
// from the recording index.
// Usage: bench_live_viewers [SECONDS] [VIEWERS]   (default 20 s, 50 viewers)
#include <poll.h>
#include <signal.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "bench_arguments.h"
#include "child_process.h"
#include "free_port.h"

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using wircam::bench::spawn;
using wircam::bench::stopGroup;

// A /proc/PID/status field in kB: VmRSS (now) or VmHWM (the peak).
long statusKb(pid_t pid, const std::string& field) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  for (std::string line; std::getline(status, line);)
    if (line.starts_with(field + ":")) return std::atol(line.c_str() + field.size() + 1);
  return 0;
}
long rssKb(pid_t pid) { return statusKb(pid, "VmRSS"); }

// User + system CPU seconds so far, from /proc/PID/stat.
double cpuSeconds(pid_t pid) {
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string text((std::istreambuf_iterator<char>(stat)), {});
  auto fields = text.substr(text.rfind(')') + 2);
  std::istringstream in(fields);
  std::string skip;
  for (int i = 3; i < 14; ++i) in >> skip;
  long user = 0, system = 0;
  in >> user >> system;
  return static_cast<double>(user + system) / static_cast<double>(sysconf(_SC_CLK_TCK));
}

struct Viewers {
  double fastFps = 0;     // frames per second each reading viewer got
  long rssMiddleKb = 0;   // the server's memory half-way
  long rssEndKb = 0;      // and at the end
  long peakKb = 0;        // its peak (VmHWM), at the end
  double cpuSeconds = 0;  // what the server used while watched
  int connected = 0;      // of the viewers asked for
};

// What one viewer asks for and how it counts the frames that come.
struct ViewerKind {
  // Sends the request on a new connection (false: it was refused).
  std::function<bool(int socket)> open;
  // A fresh counter for one viewer: takes each read, returns frames so far.
  std::function<std::function<long(std::string_view)>()> counter;
};

// An MJPEG viewer of `path`: parts counted by their boundary, which may
// straddle two reads.
ViewerKind mjpegViewer(const std::string& path) {
  return {[path](int socket) {
            std::string request = "GET " + path + " HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n";
            return ::send(socket, request.data(), request.size(), MSG_NOSIGNAL) > 0;
          },
          [] {
            return [parts = 0L, tail = std::string()](std::string_view read) mutable {
              std::string text = tail + std::string(read);
              for (size_t at = text.find("--wircframe"); at != std::string::npos;
                   at = text.find("--wircframe", at + 1))
                ++parts;
              tail = text.substr(text.size() > 10 ? text.size() - 10 : 0);
              return parts;
            };
          }};
}

// A Foxglove client subscribed to the first camera's image (channel 1): the
// WebSocket handshake, then a masked subscribe; binary frames counted by
// walking the WebSocket framing.
ViewerKind foxgloveViewer() {
  return {
      [](int socket) {
        std::string request =
            "GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nUpgrade: websocket\r\nConnection: "
            "Upgrade\r\nSec-WebSocket-Key: d2lyY2FtLWJlbmNoLWtleQ==\r\n"
            "Sec-WebSocket-Version: 13\r\nSec-WebSocket-Protocol: foxglove.websocket.v1\r\n\r\n";
        if (::send(socket, request.data(), request.size(), MSG_NOSIGNAL) <= 0) return false;
        // The 101 and its headers, byte by byte so nothing after them is taken.
        std::string answer;
        for (char c; !answer.ends_with("\r\n\r\n") && ::recv(socket, &c, 1, 0) == 1;) answer += c;
        if (!answer.starts_with("HTTP/1.1 101")) return false;
        std::string subscribe = R"({"op":"subscribe","subscriptions":[{"id":0,"channelId":1}]})";
        std::string frame = {'\x81', static_cast<char>(0x80 | subscribe.size()), 0, 0, 0, 0};
        frame += subscribe;  // masked with a zero key: the bytes as they are
        return ::send(socket, frame.data(), frame.size(), MSG_NOSIGNAL) > 0;
      },
      [] {
        // Where the next frame's header starts, in bytes still to skip.
        return [frames = 0L, skip = uint64_t{0},
                header = std::string()](std::string_view read) mutable {
          while (!read.empty()) {
            if (skip > 0) {
              uint64_t n = std::min<uint64_t>(skip, read.size());
              skip -= n;
              read.remove_prefix(n);
              continue;
            }
            header += read[0];
            read.remove_prefix(1);
            if (header.size() < 2) continue;
            uint8_t length7 = static_cast<uint8_t>(header[1]) & 0x7f;
            size_t needed = length7 == 126 ? 4 : length7 == 127 ? 10 : 2;
            if (header.size() < needed) continue;
            uint64_t length = length7;
            if (length7 >= 126) {
              length = 0;
              for (size_t i = 2; i < needed; ++i)
                length = length << 8 | static_cast<uint8_t>(header[i]);
            }
            if ((header[0] & 0x0f) == 2) ++frames;  // binary: a message
            skip = length;
            header.clear();
          }
          return frames;
        };
      }};
}

// Opens `count` connections to port, each a `kind` viewer; the first half
// reads everything (counting the frames), the other half never reads.
// Runs for `seconds`.
Viewers watch(pid_t server, uint16_t port, const ViewerKind& kind, int count, double seconds) {
  std::vector<wircam::UniqueFd> sockets;
  auto connecting = Clock::now();  // frames come from the first connection on
  for (auto until = Clock::now() + std::chrono::seconds(10);
       static_cast<int>(sockets.size()) < count && Clock::now() < until;) {
    auto socket = wircam::connectTcp(wircam::SocketAddress::loopback(port));
    if (!socket || !kind.open(socket->get())) {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
      continue;
    }
    sockets.push_back(std::move(*socket));
  }
  // Half of those that got in read; a server that turned some away says so.
  int readers = static_cast<int>(sockets.size()) / 2;
  std::vector<long> frames(sockets.size(), 0);
  std::vector<std::function<long(std::string_view)>> counters;
  for (size_t i = 0; i < sockets.size(); ++i) counters.push_back(kind.counter());
  Viewers result;
  result.connected = static_cast<int>(sockets.size());
  double cpuBefore = cpuSeconds(server);
  auto start = Clock::now();
  auto end =
      start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
  bool sampledMiddle = false;
  char buffer[65536];
  while (Clock::now() < end) {
    std::vector<pollfd> fds;
    for (int i = 0; i < readers && i < static_cast<int>(sockets.size()); ++i)
      fds.push_back({sockets[i].get(), POLLIN, 0});
    poll(fds.data(), fds.size(), 100);
    for (size_t i = 0; i < fds.size(); ++i) {
      if (!(fds[i].revents & POLLIN)) continue;
      ssize_t n = ::recv(fds[i].fd, buffer, sizeof buffer, MSG_DONTWAIT);
      if (n <= 0) continue;
      frames[i] = counters[i](std::string_view(buffer, static_cast<size_t>(n)));
    }
    if (!sampledMiddle && Clock::now() - start > std::chrono::duration<double>(seconds / 2)) {
      result.rssMiddleKb = rssKb(server);
      sampledMiddle = true;
    }
  }
  result.rssEndKb = rssKb(server);
  result.peakKb = statusKb(server, "VmHWM");
  result.cpuSeconds = cpuSeconds(server) - cpuBefore;
  long total = 0;
  for (int i = 0; i < readers; ++i) total += frames[i];
  double watched = std::chrono::duration<double>(Clock::now() - connecting).count();
  result.fastFps = readers ? static_cast<double>(total) / readers / watched : 0;
  return result;
}

long recordedFrames(const fs::path& folder) {
  std::ifstream in(folder / "index.json");
  auto index = nlohmann::json::parse(in, nullptr, false);
  long frames = 0;
  if (index.is_object())
    for (const auto& entry : index.value("segments", nlohmann::json::array()))
      frames += entry.value("frames", 0L);
  return frames;
}

}  // namespace

int main(int argc, char** argv) {
  auto arguments = wircam::bench::positiveArguments(
      argc, argv, {20, 50}, "usage: bench_live_viewers [SECONDS [VIEWERS]]   (default 20 s, 50)");
  if (!arguments) return 2;
  double seconds = (*arguments)[0];
  int viewers = static_cast<int>((*arguments)[1]);
  fs::path bin = fs::canonical("/proc/self/exe").parent_path();
  fs::path work = fs::temp_directory_path() / ("wircam-bench-viewers-" + std::to_string(getpid()));
  fs::create_directories(work);
  uint16_t devicePort = wircam::testing::freeLoopbackPort();
  pid_t sim = spawn((bin / "wirc-sim").string() + " --port " + std::to_string(devicePort));
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  const double warmUp = 3;  // login and the first frames before the viewers come

  std::printf("%d viewers (%d reading, %d never reading), %.0f s, one 352x288 camera at 15 fps\n",
              viewers, viewers / 2, viewers - viewers / 2, seconds);
  std::printf("%-37s | %-7s | %-6s | %-14s | %-7s | %s\n", "server", "viewers", "CPU %",
              "MB mid → end", "peak MB", "reader fps · recorded frames");
  auto row = [seconds](const char* name, int count, const Viewers& seen,
                       const std::string& recorded) {
    std::string shown = std::to_string(count);
    if (seen.connected != count) shown += " (" + std::to_string(seen.connected) + " in)";
    std::printf("%-37s | %-7s | %5.1f  | %5.1f → %-5.1f  | %6.1f  | %5.1f · %s\n", name,
                shown.c_str(), 100.0 * seen.cpuSeconds / seconds,
                static_cast<double>(seen.rssMiddleKb) / 1024,
                static_cast<double>(seen.rssEndKb) / 1024, static_cast<double>(seen.peakKb) / 1024,
                seen.fastFps, recorded.c_str());
  };
  // The plugin registry is brought up to date before anything is measured.
  std::system("gst-inspect-1.0 wircsrc > /dev/null 2>&1");
  // CPU per reading viewer, over the same server's run without viewers.
  std::map<std::string, double> cpuPerViewer;
  for (const char* server : {"--http", "--foxglove"}) {
    std::vector<double> cpu;
    for (int count : {0, viewers}) {
      fs::remove_all(work / "rec");
      uint16_t serverPort = wircam::testing::freeLoopbackPort();
      pid_t recorder = spawn(
          (bin / "wirc-recorder").string() + " --device 127.0.0.1:" + std::to_string(devicePort) +
          " --out " + (work / "rec").string() + " --segment 600 " + server +
          " 127.0.0.1:" + std::to_string(serverPort) +
          (std::string(server) == "--foxglove" ? " --foxglove-max-clients 64" : ""));
      std::this_thread::sleep_for(std::chrono::duration<double>(warmUp));
      std::string camera = "127.0.0.1-" + std::to_string(devicePort) + "-cam0";
      auto recordingStart = Clock::now();
      bool foxglove = std::string(server) == "--foxglove";
      Viewers seen = watch(recorder, serverPort,
                           foxglove ? foxgloveViewer() : mjpegViewer("/live/" + camera + ".mjpg"),
                           count, seconds);
      double recorded =
          std::chrono::duration<double>(Clock::now() - recordingStart).count() + warmUp;
      stopGroup(recorder, SIGINT);  // it closes its segment and index
      char text[64];
      std::snprintf(text, sizeof text, "%ld in %.1f s", recordedFrames(work / "rec"), recorded);
      row(foxglove ? "wirc-recorder --foxglove" : "wirc-recorder --http", count, seen, text);
      cpu.push_back(seen.cpuSeconds);
    }
    cpuPerViewer[server] = (cpu[1] - cpu[0]) / seconds / (viewers / 2) * 100;
  }
  for (int count : {0, viewers}) {
    uint16_t tcpPort = wircam::testing::freeLoopbackPort();
    pid_t launch =
        spawn("gst-launch-1.0 -q wircsrc host=127.0.0.1 port=" + std::to_string(devicePort) +
              " ! multipartmux boundary=wircframe ! tcpserversink host=127.0.0.1 port=" +
              std::to_string(tcpPort));
    std::this_thread::sleep_for(std::chrono::duration<double>(warmUp));
    Viewers seen = watch(launch, tcpPort, mjpegViewer("/"), count, seconds);
    stopGroup(launch, SIGINT);
    row("stock: multipartmux ! tcpserversink", count, seen, "(does not record)");
  }
  std::printf("CPU per reading viewer over none: MJPEG %.2f %%, Foxglove %.2f %% (%.2fx)\n",
              cpuPerViewer["--http"], cpuPerViewer["--foxglove"],
              cpuPerViewer["--foxglove"] / cpuPerViewer["--http"]);
  stopGroup(sim, SIGINT);
  fs::remove_all(work);
  return 0;
}
