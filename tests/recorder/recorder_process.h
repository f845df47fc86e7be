// wirc-recorder as users run it: a separate process with its own folder,
// and what the tests read back from its files.
#pragma once

#include <gst/gst.h>
#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace wircam::testing {

class RecorderProcess {
 public:
  // Records from 127.0.0.1:port into a fresh folder (`out()`); with port 0
  // the device and the folder come from `extra` alone. `wrapper` runs in
  // front of the recorder (e.g. a shell that mounts a small file system).
  RecorderProcess(uint16_t port, std::vector<std::string> extra,
                  std::vector<std::string> wrapper = {});
  ~RecorderProcess();
  RecorderProcess(const RecorderProcess&) = delete;
  RecorderProcess& operator=(const RecorderProcess&) = delete;

  // The exit code, or 128 + signal.
  int wait();
  // The same, or nullopt if it is still running after `timeout` (not
  // stretched: callers stretch what only bounds a failure).
  std::optional<int> waitExit(std::chrono::milliseconds timeout);
  void signal(int number);
  pid_t pid() const { return pid_; }
  const std::filesystem::path& out() const { return out_; }
  // The recordings with this extension (".mkv"), sorted by name.
  std::vector<std::filesystem::path> files(const std::string& extension) const;
  // Everything the recorder wrote to stderr so far.
  std::string log() const;
  // Its status display (stdout) so far.
  std::string statusLines() const;
  // The first word starting with `prefix` in the log (e.g. "http://"), or
  // nullopt after `timeout` (stretched under a sanitizer).
  std::optional<std::string> waitForLog(const std::string& prefix,
                                        std::chrono::milliseconds timeout);
  // Whether the log says `text` (anywhere) within `timeout` (stretched
  // likewise).
  bool waitForText(const std::string& text, std::chrono::milliseconds timeout) const;

 private:
  std::filesystem::path folder_;  // out_ and the log
  std::filesystem::path out_;
  pid_t pid_ = -1;
  bool exited_ = false;
  int status_ = 0;
};

GstClockTime durationOf(const std::filesystem::path& file);

// What one recorded file holds, read back through its demuxer.
struct Contents {
  int frames = 0;
  bool monotonic = true;  // the frames' timestamps rise
  std::vector<GstClockTime> framePts;
  std::string videoCaps;               // the video stream's media type, e.g. "image/jpeg"
  std::vector<std::string> telemetry;  // the text track, one JSON per buffer
};
Contents contentsOf(const std::filesystem::path& file);

// The MD5 of each video frame's bytes (JPEG or H.264), in file order
// (Matroska or MP4).
std::vector<std::string> frameDigests(const std::filesystem::path& file);

// What ffmpeg says as it decodes every frame of `file`: empty when it says
// nothing. At the file's own times (-enc_time_base -1): left to itself,
// ffmpeg re-times the frames on the stream's guessed rate, where two that
// arrived a few milliseconds apart (the burst after a stall) share a tick
// and it calls that a non-monotonic timestamp.
std::string ffmpegDecodeErrors(const std::filesystem::path& file);
// How many frames ffprobe decodes of `file`'s video, as it prints it ("45\n").
std::string decodedFrameCount(const std::filesystem::path& file);

}  // namespace wircam::testing
