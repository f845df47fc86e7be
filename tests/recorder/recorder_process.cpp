#include "recorder_process.h"

#include <gst/app/gstappsink.h>
#include <gst/pbutils/pbutils.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "gst_scoped.h"
#include "shell_command.h"
#include "wait_for.h"

namespace wircam::testing {

namespace fs = std::filesystem;

RecorderProcess::RecorderProcess(uint16_t port, std::vector<std::string> extra,
                                 std::vector<std::string> wrapper) {
  // A folder no other run has: named by the process, a folder could be
  // one left by an earlier process of the same number, or by its recorder
  // still writing (when that test was cut off).
  std::string pattern = (fs::temp_directory_path() / "wirc-recorder-test-XXXXXX").string();
  if (!mkdtemp(pattern.data())) throw std::runtime_error("mkdtemp: " + pattern);
  folder_ = pattern;
  out_ = folder_ / "out";
  std::vector<std::string> args = wrapper;
  args.insert(args.end(), {WIRC_RECORDER, "--status", "0.5"});
  if (port != 0)
    args.insert(args.end(), {"--device", "127.0.0.1:" + std::to_string(port), "--out", out_});
  args.insert(args.end(), extra.begin(), extra.end());
  std::string log = folder_ / "stderr.log";
  pid_ = fork();
  if (pid_ == 0) {
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    std::string status = folder_ / "stdout.log";
    if (!freopen(status.c_str(), "w", stdout) || !freopen(log.c_str(), "w", stderr)) _exit(126);
    execvp(argv[0], argv.data());
    _exit(127);
  }
}

namespace {

// Where each thread of a running process stands, by gdb (when installed):
// a test that failed on a recorder that stopped answering shows why.
std::string threadsOf(pid_t pid) {
  if (runCommand("command -v gdb").exitCode != 0) return "(gdb is not installed)\n";
  return commandOutput("timeout 60 gdb -p " + std::to_string(pid) +
                       " -batch -nx -ex 'thread apply all bt 12' 2>/dev/null | grep -E "
                       "'^(Thread|#)'");
}

std::string tail(std::string text, size_t size) {
  return text.size() > size ? "...\n" + text.substr(text.size() - size) : text;
}

}  // namespace

RecorderProcess::~RecorderProcess() {
  // The folder goes away with the test: a failing test shows why the
  // recorder did what it did (its threads, its errors, a sanitizer's
  // report) first.
  bool failed = ::testing::Test::HasFailure();
  // The log as it was before gdb stopped the recorder: gdb holds every
  // thread while it reads them (3.5 s in CI, 27 s once under load), and
  // what the recorder then logs of its own silence (a link timed out, a
  // peer gone) is the dump's doing, not what failed the test.
  std::string logBeforeDump = failed ? log() : "";
  if (!exited_) {
    if (failed)
      std::fprintf(stderr, "--- wirc-recorder's threads ---\n%s--- end of its threads ---\n",
                   tail(threadsOf(pid_), 64 * 1024).c_str());
    kill(pid_, SIGKILL);
    wait();
  }
  if (failed)
    std::fprintf(stderr, "--- wirc-recorder's log (%s) ---\n%s--- end of its log ---\n",
                 folder_.c_str(), tail(logBeforeDump, 64 * 1024).c_str());
  std::error_code ignored;  // a destructor that throws ends the program
  fs::remove_all(folder_, ignored);
}

int RecorderProcess::wait() {
  if (!exited_) waitpid(pid_, &status_, 0);
  exited_ = true;
  return WIFEXITED(status_) ? WEXITSTATUS(status_) : 128 + WTERMSIG(status_);
}

std::optional<int> RecorderProcess::waitExit(std::chrono::milliseconds timeout) {
  auto end = std::chrono::steady_clock::now() + timeout;
  while (!exited_) {
    if (waitpid(pid_, &status_, WNOHANG) == pid_) {
      exited_ = true;
      break;
    }
    if (std::chrono::steady_clock::now() >= end) return std::nullopt;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return wait();
}

void RecorderProcess::signal(int number) { kill(pid_, number); }

std::string RecorderProcess::statusLines() const {
  std::ifstream in(folder_ / "stdout.log");
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::vector<fs::path> RecorderProcess::files(const std::string& extension) const {
  std::vector<fs::path> found;
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(out_, error))
    if (entry.path().extension() == extension) found.push_back(entry.path());
  std::sort(found.begin(), found.end());
  return found;
}

std::string RecorderProcess::log() const {
  std::ifstream file(folder_ / "stderr.log");
  return std::string((std::istreambuf_iterator<char>(file)), {});
}

std::optional<std::string> RecorderProcess::waitForLog(const std::string& prefix,
                                                       std::chrono::milliseconds timeout) {
  auto deadline = std::chrono::steady_clock::now() + patience(timeout);
  while (std::chrono::steady_clock::now() < deadline) {
    std::istringstream words(log());
    std::string word;
    while (words >> word)
      if (word.rfind(prefix, 0) == 0) return word;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return std::nullopt;
}

bool RecorderProcess::waitForText(const std::string& text,
                                  std::chrono::milliseconds timeout) const {
  return waitFor([&] { return log().find(text) != std::string::npos; }, timeout);
}

GstClockTime durationOf(const fs::path& file) {
  GstDiscoverer* discoverer = gst_discoverer_new(10 * GST_SECOND, nullptr);
  std::string uri = "file://" + fs::absolute(file).string();
  GstDiscovererInfo* info = gst_discoverer_discover_uri(discoverer, uri.c_str(), nullptr);
  GstClockTime duration = info ? gst_discoverer_info_get_duration(info) : GST_CLOCK_TIME_NONE;
  if (info) gst_discoverer_info_unref(info);
  g_object_unref(discoverer);
  return duration;
}

namespace {

struct Reading {
  Contents contents;
  GstClockTime last = GST_CLOCK_TIME_NONE;
  GstElement* pipeline;
};

GstPadProbeReturn onVideo(GstPad* pad, GstPadProbeInfo* info, gpointer data) {
  auto* r = static_cast<Reading*>(data);
  GstBuffer* buffer = GST_PAD_PROBE_INFO_BUFFER(info);
  GstClockTime pts = GST_BUFFER_PTS(buffer);
  if (GST_CLOCK_TIME_IS_VALID(r->last) && pts <= r->last) r->contents.monotonic = false;
  r->last = pts;
  ++r->contents.frames;
  r->contents.framePts.push_back(pts);
  if (r->contents.videoCaps.empty()) {
    GstCaps* caps = gst_pad_get_current_caps(pad);
    r->contents.videoCaps = gst_structure_get_name(gst_caps_get_structure(caps, 0));
    gst_caps_unref(caps);
  }
  return GST_PAD_PROBE_OK;
}

// matroskademux gives UTF-8 text as Pango markup: the JSON's quotes come
// out as &quot; and so on.
std::string unescapeMarkup(std::string text) {
  for (auto [entity, plain] :
       {std::pair{"&quot;", "\""}, {"&apos;", "'"}, {"&lt;", "<"}, {"&gt;", ">"}, {"&amp;", "&"}}) {
    std::string e = entity;
    for (size_t at = text.find(e); at != std::string::npos; at = text.find(e, at + 1))
      text.replace(at, e.size(), plain);
  }
  return text;
}

GstPadProbeReturn onText(GstPad* pad, GstPadProbeInfo* info, gpointer data) {
  GstBuffer* buffer = GST_PAD_PROBE_INFO_BUFFER(info);
  GstCaps* caps = gst_pad_get_current_caps(pad);
  const char* format = gst_structure_get_string(gst_caps_get_structure(caps, 0), "format");
  bool markup = format && std::string(format) == "pango-markup";
  gst_caps_unref(caps);
  // Empty buffers are the recorder's heartbeats (they carry no line).
  if (gst_buffer_get_size(buffer) == 0) return GST_PAD_PROBE_OK;
  if (gst::ScopedBufferMap map(buffer, GST_MAP_READ); map) {
    std::string text(map.view());
    static_cast<Reading*>(data)->contents.telemetry.push_back(markup ? unescapeMarkup(text) : text);
  }
  return GST_PAD_PROBE_OK;
}

// Each demuxed stream ends in a fakesink; a probe counts what passes.
void onPadAdded(GstElement*, GstPad* pad, gpointer data) {
  auto* r = static_cast<Reading*>(data);
  GstElement* sink = gst_element_factory_make("fakesink", nullptr);
  g_object_set(sink, "sync", FALSE, "async", FALSE, nullptr);
  gst_bin_add(GST_BIN(r->pipeline), sink);
  gst_element_sync_state_with_parent(sink);
  GstPad* sinkPad = gst_element_get_static_pad(sink, "sink");
  gst_pad_link(pad, sinkPad);
  gst_object_unref(sinkPad);
  bool text = std::string(GST_PAD_NAME(pad)).rfind("subtitle", 0) == 0;
  gst_pad_add_probe(pad, GST_PAD_PROBE_TYPE_BUFFER, text ? onText : onVideo, r, nullptr);
}

}  // namespace

std::vector<std::string> frameDigests(const fs::path& file) {
  std::string description = "filesrc location=\"" + file.string() + "\" ! " +
                            (file.extension() == ".mp4" ? "qtdemux" : "matroskademux") +
                            " ! appsink name=sink sync=false caps=\"image/jpeg;video/x-h264\"";
  GstElement* pipeline = gst_parse_launch(description.c_str(), nullptr);
  GstElement* sink = gst_bin_get_by_name(GST_BIN(pipeline), "sink");
  gst_element_set_state(pipeline, GST_STATE_PLAYING);
  std::vector<std::string> digests;
  // A file that does not demux ends the frames (a wait, not a hang).
  while (GstSample* sample = gst_app_sink_try_pull_sample(GST_APP_SINK(sink), 10 * GST_SECOND)) {
    if (gst::ScopedBufferMap map(gst_sample_get_buffer(sample), GST_MAP_READ); map) {
      gchar* md5 = g_compute_checksum_for_data(G_CHECKSUM_MD5, map.data(), map.size());
      digests.emplace_back(md5);
      g_free(md5);
    }
    gst_sample_unref(sample);
  }
  gst_element_set_state(pipeline, GST_STATE_NULL);
  gst_object_unref(sink);
  gst_object_unref(pipeline);
  return digests;
}

std::string ffmpegDecodeErrors(const fs::path& file) {
  return runCommand("ffmpeg -v error -i '" + file.string() + "' -enc_time_base -1 -f null -")
      .output;
}

std::string decodedFrameCount(const fs::path& file) {
  return runCommand(
             "ffprobe -v error -count_frames -select_streams v:0 -show_entries "
             "stream=nb_read_frames -of csv=p=0 '" +
             file.string() + "'")
      .output;
}

Contents contentsOf(const fs::path& file) {
  const char* demuxer = file.extension() == ".mp4" ? "qtdemux" : "matroskademux";
  std::string description =
      "filesrc location=\"" + file.string() + "\" ! " + demuxer + " name=demux";
  Reading reading;
  reading.pipeline = gst_parse_launch(description.c_str(), nullptr);
  GstElement* demux = gst_bin_get_by_name(GST_BIN(reading.pipeline), "demux");
  g_signal_connect(demux, "pad-added", G_CALLBACK(onPadAdded), &reading);
  gst_object_unref(demux);
  gst_element_set_state(reading.pipeline, GST_STATE_PLAYING);
  GstBus* bus = gst_element_get_bus(reading.pipeline);
  if (GstMessage* message = gst_bus_timed_pop_filtered(
          bus, 20 * GST_SECOND, static_cast<GstMessageType>(GST_MESSAGE_EOS | GST_MESSAGE_ERROR)))
    gst_message_unref(message);
  gst_object_unref(bus);
  gst_element_set_state(reading.pipeline, GST_STATE_NULL);
  gst_object_unref(reading.pipeline);
  return reading.contents;
}

}  // namespace wircam::testing
