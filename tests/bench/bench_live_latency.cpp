// The live view's latency, bitrate and cost, MJPEG beside WebRTC, as a
// browser shows them: Debian's chromium (headless, over DevTools) watching
// wirc-recorder --http, which records wirc-sim's follow scene.
//
// Latency is from the device's send to the browser's presentation: wirc-sim
// --clock-stamp draws the wall clock's milliseconds into each frame as 32
// black/white blocks just before it encodes and sends it; the page reads the
// blocks back from the picture it shows and subtracts them from its own
// wall clock (the same machine's):
//   WebRTC: in requestVideoFrameCallback, at the frame's expected display
//           time (performance.timeOrigin + metadata.expectedDisplayTime);
//   MJPEG:  on the first animation frame (requestAnimationFrame, 60 Hz) that
//           shows a new picture, so up to 16.7 ms late (8 ms on average).
// So the figures include the JPEG encoding in the simulator (a few ms).
// Bitrate: WebRTC's bytesReceived (getStats) and the bytes of the MJPEG
// response, each over the same time. CPU: the recorder's (user + system,
// /proc) while 0, 1 and 10 viewers of each kind watch.
// Usage: bench_live_latency [SECONDS]   (default 10 s per measurement)
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "bench_arguments.h"
#include "child_process.h"
#include "devtools_page.h"
#include "free_port.h"

namespace {

namespace fs = std::filesystem;
using wircam::bench::cpuSecondsOf;
using wircam::bench::spawn;
using wircam::bench::stopGroup;
using wircam::testing::DevToolsPage;
using Clock = std::chrono::steady_clock;

// The page's helpers: the stamp read from a picture, and its age.
const char* kHelpers = R"JS(
window.readStamp = (source, w, h) => {
  const c = window.stampCanvas || (window.stampCanvas = document.createElement('canvas'));
  if (c.width !== w || c.height !== h) { c.width = w; c.height = h; }
  const g = c.getContext('2d', { willReadFrequently: true });
  g.drawImage(source, 0, 0, w, h);
  const bw = Math.floor(w / 32), bh = Math.max(16, Math.floor(h / 16));
  const row = g.getImageData(0, Math.floor(bh / 2), w, 1).data;
  let value = 0;
  for (let i = 0; i < 32; ++i) value = value * 2 + (row[4 * (i * bw + (bw >> 1))] > 128 ? 1 : 0);
  return value;
};
window.ageOf = (stamp, wallMs) => {
  let age = Math.floor(wallMs) % 4294967296 - stamp;
  return age < 0 ? age + 4294967296 : age;
};
window.summary = (ages, misread, extra) => {
  ages.sort((a, b) => a - b);
  const at = q => ages.length ? ages[Math.min(ages.length - 1, Math.floor(q * ages.length))] : -1;
  return Object.assign({ frames: ages.length, median: at(0.5), p90: at(0.9), misread }, extra);
};
window.offerWhep = async (camera) => {
  const pc = new RTCPeerConnection();
  pc.addTransceiver('video', { direction: 'recvonly' });
  await pc.setLocalDescription(await pc.createOffer());
  await new Promise(done => { const t = setTimeout(done, 2000);
    pc.onicegatheringstatechange = () => {
      if (pc.iceGatheringState === 'complete') { clearTimeout(t); done(); } }; });
  const r = await fetch(`/api/cameras/${camera}/whep`, { method: 'POST',
      headers: { 'Content-Type': 'application/sdp' }, body: pc.localDescription.sdp });
  if (r.status !== 201) throw new Error('WHEP ' + r.status);
  pc.where = r.headers.get('Location');
  const video = document.createElement('video');
  video.muted = true; video.autoplay = true; document.body.appendChild(video);
  pc.ontrack = e => { video.srcObject = new MediaStream([e.track]); };
  await pc.setRemoteDescription({ type: 'answer', sdp: await r.text() });
  await new Promise((done, fail) => { const t = setTimeout(() => fail(new Error('no picture: ' + pc.connectionState)), 10000);
    const check = () => video.videoWidth ? (clearTimeout(t), done()) : setTimeout(check, 20);
    check(); });
  pc.video = video;
  return pc;
};
window.closeWhep = pc => { pc.close(); pc.video.remove(); return fetch(pc.where, { method: 'DELETE' }); };
window.bytesIn = async pc => { let bytes = 0;
  (await pc.getStats()).forEach(s => { if (s.type === 'inbound-rtp') bytes = s.bytesReceived; });
  return bytes; };
)JS";

std::string mjpegLatency(const std::string& camera, double seconds) {
  return "(async () => { const img = new Image(); img.src = '/live/" + camera +
         ".mjpg'; document.body.appendChild(img); const ages = []; let last = -1, misread = 0; "
         "const end = performance.now() + " +
         std::to_string(seconds * 1000) +
         "; await new Promise(done => { const tick = t => { if (img.naturalWidth) { const s = "
         "readStamp(img, img.naturalWidth, img.naturalHeight); if (s !== last) { last = s; const "
         "a = ageOf(s, performance.timeOrigin + t); if (a < 10000) ages.push(a); else "
         "misread++; } } if (performance.now() < end) requestAnimationFrame(tick); else done(); }; "
         "requestAnimationFrame(tick); }); img.src = ''; img.remove(); return summary(ages, "
         "misread, {}); })()";
}

std::string mjpegBitrate(const std::string& camera, double seconds) {
  return "(async () => { const ctl = new AbortController(); const r = await fetch('/live/" +
         camera +
         ".mjpg', { signal: ctl.signal }); const reader = r.body.getReader(); let bytes = 0; "
         "const t0 = performance.now(); const end = t0 + " +
         std::to_string(seconds * 1000) +
         "; while (performance.now() < end) { const { value, done } = await reader.read(); if "
         "(done) break; bytes += value.length; } ctl.abort(); return bytes * 8 / "
         "(performance.now() - t0); })()";
}

std::string webrtcLatency(const std::string& camera, double seconds) {
  return "(async () => { const pc = await offerWhep('" + camera +
         "'); const video = pc.video; const b0 = await bytesIn(pc), t0 = performance.now(); "
         "const ages = []; let misread = 0; const end = t0 + " +
         std::to_string(seconds * 1000) +
         "; await new Promise(done => { const cb = (now, meta) => { const a = "
         "ageOf(readStamp(video, meta.width, meta.height), performance.timeOrigin + "
         "meta.expectedDisplayTime); if (a < 10000) ages.push(a); else misread++; if "
         "(performance.now() < end) video.requestVideoFrameCallback(cb); else done(); }; "
         "video.requestVideoFrameCallback(cb); }); const kbps = (await bytesIn(pc) - b0) * 8 / "
         "(performance.now() - t0); await closeWhep(pc); return summary(ages, misread, { kbps "
         "}); })()";
}

// `viewers` of a kind held open for `seconds` (the recorder's CPU is read
// around it); the number that came up.
std::string holdViewers(const std::string& kind, const std::string& camera, int viewers,
                        double seconds) {
  std::string wait =
      "await new Promise(d => setTimeout(d, " + std::to_string(seconds * 1000) + "));";
  if (kind == "mjpeg")
    return "(async () => { const imgs = Array.from({length: " + std::to_string(viewers) +
           "}, () => { const i = new Image(); i.src = '/live/" + camera +
           ".mjpg'; document.body.appendChild(i); return i; }); await new Promise(d => "
           "setTimeout(d, 1000)); window.holding = true; " +
           wait +
           " const up = imgs.filter(i => i.naturalWidth).length; imgs.forEach(i => { "
           "i.src = ''; i.remove(); }); return up; })()";
  return "(async () => { const pcs = await Promise.all(Array.from({length: " +
         std::to_string(viewers) + "}, () => offerWhep('" + camera + "'))); " + wait +
         " for (const pc of pcs) await closeWhep(pc); return pcs.length; })()";
}

nlohmann::json run(DevToolsPage& page, const std::string& script, double seconds) {
  auto reply = page.call("Runtime.evaluate",
                         {{"expression", script}, {"returnByValue", true}, {"awaitPromise", true}},
                         std::chrono::milliseconds(static_cast<int>(seconds * 1000) + 60000));
  if (!reply.contains("result") || reply.contains("exceptionDetails")) {
    std::fprintf(stderr, "bench_live_latency: %s\n", reply.dump().substr(0, 400).c_str());
    return nullptr;
  }
  return reply["result"].value("value", nlohmann::json());
}

}  // namespace

int main(int argc, char** argv) {
  auto arguments = wircam::bench::positiveArguments(
      argc, argv, {10}, "usage: bench_live_latency [SECONDS]   (per measurement, default 10)");
  if (!arguments) return 2;
  double seconds = (*arguments)[0];
  fs::path bin = fs::canonical("/proc/self/exe").parent_path();
  fs::path work = fs::temp_directory_path() / ("wircam-bench-latency-" + std::to_string(getpid()));
  fs::create_directories(work);
  std::system("gst-inspect-1.0 wircsrc > /dev/null 2>&1");  // the registry first
  std::printf("live view from the device's send to the browser's presentation, %.0f s each\n",
              seconds);
  std::printf("%-8s | %-6s | %-7s | %-17s | %-8s | %s\n", "size", "view", "viewers",
              "latency median/p90", "kbit/s", "recorder CPU %");
  for (const char* size : {"352x288", "1280x720"}) {
    uint16_t devicePort = wircam::testing::freeLoopbackPort(),
             httpPort = wircam::testing::freeLoopbackPort();
    pid_t sim = spawn((bin / "wirc-sim").string() + " --clock-stamp --size " + size + " --port " +
                      std::to_string(devicePort));
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    fs::remove_all(work / "rec");
    pid_t recorder = spawn((bin / "wirc-recorder").string() + " --device 127.0.0.1:" +
                           std::to_string(devicePort) + " --out " + (work / "rec").string() +
                           " --segment 600 --http 127.0.0.1:" + std::to_string(httpPort));
    std::this_thread::sleep_for(std::chrono::seconds(3));
    std::string camera = "127.0.0.1-" + std::to_string(devicePort) + "-cam0";
    auto page = DevToolsPage::launch(work / "chromium", 1400, 1000);
    if (!page || !page->navigate("http://127.0.0.1:" + std::to_string(httpPort) + "/login")) {
      std::fprintf(stderr, "bench_live_latency: chromium did not start\n");
      return 1;
    }
    run(*page, kHelpers, 1);
    auto cpuWhile = [&](const std::string& script) {
      double before = cpuSecondsOf(recorder);
      auto start = Clock::now();
      auto result = run(*page, script, seconds);
      double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
      return std::make_pair(result, 100.0 * (cpuSecondsOf(recorder) - before) / elapsed);
    };
    auto [idle, idleCpu] = cpuWhile("new Promise(d => setTimeout(() => d(0), " +
                                    std::to_string(seconds * 1000) + "))");
    std::printf("%-8s | %-6s | %-7d | %-17s | %-8s | %5.1f (recording only)\n", size, "-", 0, "-",
                "-", idleCpu);
    for (const std::string kind : {"mjpeg", "webrtc"}) {
      auto [latency, cpu] = cpuWhile(kind == "mjpeg" ? mjpegLatency(camera, seconds)
                                                     : webrtcLatency(camera, seconds));
      double kbps = kind == "mjpeg"
                        ? run(*page, mjpegBitrate(camera, seconds), seconds).get<double>()
                        : latency.value("kbps", -1.0);
      char shown[32];
      std::snprintf(shown, sizeof shown, "%d / %d ms", latency.value("median", -1),
                    latency.value("p90", -1));
      std::printf("%-8s | %-6s | %-7d | %-17s | %-8.0f | %5.1f  (%d frames read, %d misread)\n",
                  size, kind.c_str(), 1, shown, kbps, cpu, latency.value("frames", 0),
                  latency.value("misread", 0));
      auto [held, heldCpu] = cpuWhile(holdViewers(kind, camera, 10, seconds));
      std::printf("%-8s | %-6s | %-7s | %-17s | %-8s | %5.1f\n", size, kind.c_str(),
                  (std::to_string(held.is_number() ? held.get<int>() : 0) + " of 10").c_str(), "-",
                  "-", heldCpu);
    }
    std::fflush(stdout);
    page.reset();
    stopGroup(recorder, SIGINT);
    stopGroup(sim, SIGINT);
  }
  fs::remove_all(work);
  return 0;
}
