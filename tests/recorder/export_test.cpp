// wirc-export on a real recording: the simulator streams, the recorder cuts
// segments and lives through an outage, and the export is read back by
// others' readers (ffprobe, ffmpeg, GStreamer's demuxers, and for MCAP
// @mcap/core with Foxglove's schemas under node).
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "camera_checks.h"
#include "export_command.h"
#include "recorder_process.h"
#include "recording/segment_selection.h"
#include "shell_command.h"
#include "simulated_device.h"
#include "wait_for.h"

namespace {

namespace fs = std::filesystem;
using namespace wircam;

std::string contentsOfFile(const fs::path& file) {
  std::ifstream in(file);
  return std::string(std::istreambuf_iterator<char>(in), {});
}
using namespace wircam::testing;
using std::chrono::milliseconds;

std::vector<double> packetTimes(const fs::path& file) {
  std::istringstream csv(
      runCommand("ffprobe -v error -select_streams v:0 -show_entries packet=pts_time "
                 "-of csv=p=0 '" +
                 file.string() + "'")
          .output);
  std::vector<double> times;
  for (std::string line; std::getline(csv, line);) times.push_back(std::stod(line));
  return times;
}

// The text track's default flag and title, as ffprobe reads them:
// "0,telemetry\n" when it is named and not shown.
std::string telemetryTrackOf(const fs::path& file) {
  return runCommand(
             "ffprobe -v error -select_streams s:0 -show_entries "
             "stream_disposition=default:stream_tags=title -of csv=p=0 '" +
             file.string() + "'")
      .output;
}

// One recording for every test: segments of 2 s, and an outage between.
class Export : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    auto device = startSequenceDevice();
    uint16_t port = device->port();
    recorder_ = new RecorderProcess(port, {"--segment", "2"});
    camera_ = new std::string(cameraName(port));
    ASSERT_TRUE(waitFor([] { return recorder_->files(".mkv").size() >= 2; }, milliseconds(15000)))
        << recorder_->log();
    HeldPort off = switchOff(device);
    ASSERT_TRUE(recorder_->waitForText("retrying in 400 ms", milliseconds(10000)))
        << recorder_->log();
    device = switchOn(off);
    ASSERT_TRUE(waitFor([] { return recorder_->files(".mkv").size() >= 4; }, milliseconds(15000)))
        << recorder_->log();
    recorder_->signal(SIGINT);
    ASSERT_EQ(recorder_->wait(), 0) << recorder_->log();
  }
  static void TearDownTestSuite() {
    delete recorder_;
    delete camera_;
  }

  static nlohmann::json segments() {
    return nlohmann::json::parse(std::ifstream(recorder_->out() / "index.json"))["segments"];
  }
  static fs::path output(const std::string& name) { return recorder_->out().parent_path() / name; }
  // Every frame of the recording, in order.
  static std::vector<std::string> recordedDigests(size_t from = 0, size_t to = SIZE_MAX) {
    std::vector<std::string> all;
    auto files = recorder_->files(".mkv");
    for (size_t i = from; i < std::min(to, files.size()); ++i)
      for (auto& d : frameDigests(files[i])) all.push_back(d);
    return all;
  }

  static RecorderProcess* recorder_;
  static std::string* camera_;
};
RecorderProcess* Export::recorder_ = nullptr;
std::string* Export::camera_ = nullptr;

TEST_F(Export, AllOfItAsMatroskaIsEveryFrameUntouchedOnOneTimelineWithTheOutageAsAGap) {
  fs::path out = output("all.mkv");
  auto ran = runCommand(
      exportCommand(recorder_->out(), *camera_, "--format mkv --out '" + out.string() + "'"));
  ASSERT_EQ(ran.exitCode, 0) << ran.output;
  uint64_t indexed = 0;
  for (const auto& segment : segments()) indexed += segment["frames"].get<uint64_t>();
  EXPECT_NE(ran.output.find(std::to_string(indexed) + " frames from"), std::string::npos)
      << ran.output;
  EXPECT_EQ(frameDigests(out), recordedDigests());
  EXPECT_EQ(frameDigests(out).size(), indexed);
  auto times = packetTimes(out);
  ASSERT_FALSE(times.empty());
  EXPECT_EQ(times.front(), 0);
  double widest = 0;
  for (size_t i = 1; i < times.size(); ++i) {
    EXPECT_GT(times[i], times[i - 1]) << i;
    widest = std::max(widest, times[i] - times[i - 1]);
  }
  EXPECT_GT(widest, 0.4);  // the outage (the device off, the login's backoff)
  // Only the outage: after it each frame is at its own time again, so the
  // export lasts as long as the recording did.
  size_t gaps = 0;
  for (size_t i = 1; i < times.size(); ++i) gaps += times[i] - times[i - 1] > 0.4;
  EXPECT_EQ(gaps, 1u);
  auto index = segments();
  double recorded = (*recorder::parseIsoTime(index.back()["start_utc"]) -
                     *recorder::parseIsoTime(index.front()["start_utc"])) /
                        1e9 +
                    index.back()["duration_s"].get<double>();
  EXPECT_NEAR(times.back(), recorded, 0.5);
  EXPECT_EQ(ffmpegDecodeErrors(out), "");
  // The telemetry: a named text track, and the same lines re-based beside.
  EXPECT_EQ(telemetryTrackOf(out), "0,telemetry\n");
  auto track = contentsOf(out).telemetry;
  std::ifstream jsonl(fs::path(out).replace_extension(".jsonl"));
  std::vector<nlohmann::json> lines;
  for (std::string line; std::getline(jsonl, line);) lines.push_back(nlohmann::json::parse(line));
  EXPECT_EQ(lines.size(), track.size());
  size_t sidecarLines = 0;
  for (const auto& video : recorder_->files(".mkv")) {
    std::ifstream sidecar(fs::path(video).replace_extension(".jsonl"));
    for (std::string line; std::getline(sidecar, line);) ++sidecarLines;
  }
  EXPECT_EQ(lines.size(), sidecarLines);
  bool loggedIn = false;
  for (const auto& line : lines) {
    EXPECT_GE(line["pts"].get<int64_t>(), 0) << line;
    EXPECT_LE(line["pts"].get<double>() / 1e9, times.back() + 0.5) << line;
    loggedIn |= line.dump().find("logged in") != std::string::npos;
  }
  EXPECT_TRUE(loggedIn);
}

// --out -: the file on stdout as it is made (here into a file, which
// wirc-export cannot go back over either): the same frames, the telemetry
// track named and not shown, no .jsonl, and the summary on stderr.
TEST_F(Export, StreamedToStdoutItHoldsWhatTheFileHolds) {
  for (const char* format : {"mkv", "mcap"}) {
    fs::path out = output(std::string("streamed.") + format);
    // (Braced: runCommand's 2>&1 then takes the messages, not the file.)
    auto ran = runCommand("{ " + exportCommand(recorder_->out(), *camera_,
                                               std::string("--format ") + format + " --out - > '" +
                                                   out.string() + "'; }"));
    ASSERT_EQ(ran.exitCode, 0) << ran.output;
    EXPECT_NE(ran.output.find("wirc-export: -: "), std::string::npos) << ran.output;
    EXPECT_FALSE(fs::exists(fs::path(out).replace_extension(".jsonl")));
    if (std::string(format) == "mcap") {
      auto checked = runCommand("node '" MCAP_CHECK_DIR "/check.mjs' '" + out.string() + "'");
      ASSERT_EQ(checked.exitCode, 0) << checked.output;
      auto result = nlohmann::json::parse(checked.output);
      EXPECT_EQ(result["invalid"], nlohmann::json::array());
      EXPECT_EQ(result["images"].size(), recordedDigests().size());
      continue;
    }
    EXPECT_EQ(frameDigests(out), recordedDigests());
    EXPECT_EQ(ffmpegDecodeErrors(out), "");
    EXPECT_EQ(telemetryTrackOf(out), "0,telemetry\n");
  }
}

TEST_F(Export, ARangeHoldsTheFramesOfTheSegmentsInIt) {
  auto index = segments();
  ASSERT_GE(index.size(), 4u);
  // From the second segment's first frame to just before the fourth's.
  std::string start = index[1]["start_utc"];
  std::string end = shiftedIso(index[3]["start_utc"], -1);  // just before the fourth
  fs::path out = output("range.mkv");
  auto ran = runCommand(exportCommand(
      recorder_->out(), *camera_,
      "--start " + start + " --end " + end + " --format mkv --out '" + out.string() + "'"));
  ASSERT_EQ(ran.exitCode, 0) << ran.output;
  EXPECT_EQ(frameDigests(out), recordedDigests(1, 3));
  EXPECT_EQ(frameDigests(out).size(),
            index[1]["frames"].get<size_t>() + index[2]["frames"].get<size_t>());
}

TEST_F(Export, McapIsReadByMcapCoreWithEveryMessageValidAgainstFoxglovesSchemas) {
  fs::path out = output("all.mcap");
  auto ran = runCommand(
      exportCommand(recorder_->out(), *camera_, "--format mcap --out '" + out.string() + "'"));
  ASSERT_EQ(ran.exitCode, 0) << ran.output;
  auto checked = runCommand("node '" MCAP_CHECK_DIR "/check.mjs' '" + out.string() + "'");
  ASSERT_EQ(checked.exitCode, 0)
      << checked.output << "\n(run tools/run-tests, which installs the checker's npm packages)";
  auto result = nlohmann::json::parse(checked.output);
  EXPECT_EQ(result["invalid"], nlohmann::json::array()) << result["invalid"];
  EXPECT_FALSE(result.contains("streamError")) << result["streamError"];
  EXPECT_TRUE(result["streamDone"].get<bool>());
  EXPECT_TRUE(result["ordered"].get<bool>());
  std::string topic = "/" + *camera_;
  auto recorded = recordedDigests();
  EXPECT_EQ(result["topics"][topic + "/image"], recorded.size());
  EXPECT_GT(result["topics"][topic + "/telemetry"].get<int>(), 3);
  EXPECT_GE(result["topics"][topic + "/log"].get<int>(), 2);  // two logins at least
  std::vector<std::string> images;
  for (const auto& image : result["images"]) {
    images.push_back(image["md5"]);
    EXPECT_EQ(image["format"], "jpeg");
  }
  EXPECT_EQ(images, recorded);
  // Images as Foxglove's protobuf, decoded with Foxglove's own definitions;
  // telemetry as JSON.
  EXPECT_EQ(result["encodings"][topic + "/image"], "protobuf");
  EXPECT_EQ(result["encodings"][topic + "/telemetry"], "json");
  // Each line at its own time, those of the outage too (the loss, the
  // retries, the new login): log_time is the line's utc, and a Log's
  // timestamp its log_time.
  EXPECT_GT(result["linesTimed"].get<int>(), 3);
  EXPECT_EQ(result["linesOffTheirUtc"], nlohmann::json::array()) << result["linesOffTheirUtc"];
  EXPECT_EQ(result["logsOffTheirTimestamp"], 0);
  // Seekable: chunks in the index, and a read from the middle starts there.
  EXPECT_GE(result["chunks"].get<int>(), 2);
  auto seek = result["seek"];
  EXPECT_GE(std::stoull(seek["first"].get<std::string>()),
            std::stoull(seek["from"].get<std::string>()));
  EXPECT_LT(seek["messages"].get<size_t>(), result["statistics"]["messages"].get<size_t>());
}

TEST_F(Export, SaysWhyWhenThereIsNothingToExport) {
  fs::path out = output("none.mkv");
  auto unknown = runCommand(
      exportCommand(recorder_->out(), "nosuch-cam0", "--format mkv --out '" + out.string() + "'"));
  EXPECT_EQ(unknown.exitCode, 1);
  EXPECT_NE(unknown.output.find("no camera nosuch-cam0"), std::string::npos) << unknown.output;
  EXPECT_NE(unknown.output.find(*camera_), std::string::npos) << unknown.output;  // those there are
  // A name of any length is said by its start (50 KB went whole into an
  // answer and the recorder's log, a stranger's trial).
  auto longName = runCommand(exportCommand(recorder_->out(), std::string(5000, 'c'),
                                           "--format mkv --out '" + out.string() + "'"));
  EXPECT_EQ(longName.exitCode, 1);
  EXPECT_NE(longName.output.find("no camera " + std::string(80, 'c') + "…"), std::string::npos)
      << longName.output.substr(0, 300);
  EXPECT_LT(longName.output.size(), 1000u);
  // A folder that is not there: the file asked for is named (it was the
  // sidecar's name, the first file opened).
  auto nowhere = runCommand(
      exportCommand(recorder_->out(), *camera_, "--format mkv --out /nonexistent/dir/x.mkv"));
  EXPECT_EQ(nowhere.exitCode, 1);
  EXPECT_NE(nowhere.output.find("cannot write /nonexistent/dir/x.mkv"), std::string::npos)
      << nowhere.output;
  auto before = runCommand(
      exportCommand(recorder_->out(), *camera_,
                    "--end 2001-01-01T00:00:00Z --format mkv --out '" + out.string() + "'"));
  EXPECT_EQ(before.exitCode, 1);
  EXPECT_NE(before.output.find("no frame in that range"), std::string::npos) << before.output;
  EXPECT_FALSE(fs::exists(out));
  auto malformed = runCommand(exportCommand(
      recorder_->out(), *camera_, "--start yesterday --format mkv --out '" + out.string() + "'"));
  EXPECT_EQ(malformed.exitCode, 2);
  EXPECT_NE(malformed.output.find("--start 'yesterday' is not an ISO 8601 time"), std::string::npos)
      << malformed.output;
  // A camera whose first segment is still being written is named as such.
  fs::path starting = output("starting");
  fs::remove_all(starting);
  fs::create_directories(starting);
  std::ofstream(starting / "index.json") << R"({"segments":[]})";
  auto files = recorder_->files(".mkv");
  fs::copy_file(files[0], starting / files[0].filename());
  auto first =
      runCommand(exportCommand(starting, *camera_, "--format mkv --out '" + out.string() + "'"));
  EXPECT_EQ(first.exitCode, 1);
  EXPECT_NE(first.output.find("camera " + *camera_ + " has no finished segment yet: " +
                              files[0].filename().string() + " is still being written"),
            std::string::npos)
      << first.output;
  auto mp4 = runCommand(
      exportCommand(recorder_->out(), *camera_, "--format mp4 --out '" + out.string() + "'"));
  EXPECT_EQ(mp4.exitCode, 1);
  EXPECT_NE(mp4.output.find("mp4 needs H.264 recordings"), std::string::npos) << mp4.output;
}

TEST_F(Export, ADeletedIndexIsRebuiltAndABrokenSegmentSkippedWithAWord) {
  fs::path copy = output("copy");
  fs::remove_all(copy);
  fs::copy(recorder_->out(), copy);
  fs::remove(copy / "index.json");
  auto files = recorder_->files(".mkv");
  // The second segment cut off after 3000 bytes: its first frames or none.
  fs::resize_file(copy / files[1].filename(), 3000);
  fs::path out = output("rebuilt.mkv");
  auto ran = runCommand(exportCommand(copy, *camera_, "--format mkv --out '" + out.string() + "'"));
  ASSERT_EQ(ran.exitCode, 0) << ran.output;
  EXPECT_NE(ran.output.find("no index.json: rebuilt from"), std::string::npos) << ran.output;
  auto exported = frameDigests(out);
  auto whole = recordedDigests();
  size_t lost = frameDigests(files[1]).size();
  // Every frame of the other segments, and at most the readable start of the broken one.
  EXPECT_GE(exported.size(), whole.size() - lost);
  EXPECT_LT(exported.size(), whole.size());
  EXPECT_EQ(ffmpegDecodeErrors(out), "");
}

// What a power loss, a killed process or a user can leave where a segment
// was: zeros, nothing, random bytes, text. Each is given up within its
// bound and said; the export holds every frame of the others.
TEST_F(Export, SegmentsOfZerosEmptyRandomOrTextAreSkippedInBoundedTimeAndSaid) {
  fs::path copy = output("damaged");
  fs::remove_all(copy);
  fs::copy(recorder_->out(), copy);
  auto files = recorder_->files(".mkv");
  ASSERT_GE(files.size(), 4u);
  std::vector<std::string> damaged;
  for (size_t i = 1; i <= 3; ++i) damaged.push_back(files[i].filename().string());
  std::ofstream(copy / damaged[0], std::ios::binary | std::ios::trunc)
      << std::string(64 * 1024, '\0');
  std::ofstream(copy / damaged[1], std::ios::binary | std::ios::trunc);  // empty
  {
    std::ofstream random(copy / damaged[2], std::ios::binary | std::ios::trunc);
    uint32_t x = 12345;
    for (int i = 0; i < 64 * 1024; ++i)
      random.put(static_cast<char>((x = x * 1103515245 + 12345) >> 16));
  }
  fs::path text = copy / (files[0].stem().string() + "_9.mkv");
  std::ofstream(text) << "not a recording\n";
  // Not in the index, and not written to for an hour: not the one a
  // recorder is writing, so it is read, and skipped.
  fs::last_write_time(text, fs::file_time_type::clock::now() - std::chrono::hours(1));
  fs::path out = output("damaged.mkv");
  auto started = std::chrono::steady_clock::now();
  auto ran = runCommand("timeout 30 " +
                        exportCommand(copy, *camera_, "--format mkv --out '" + out.string() + "'"));
  double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  ASSERT_EQ(ran.exitCode, 0) << ran.output;
  EXPECT_LT(seconds, 4 * 2.0 + 3);  // 2 s a file at most
  for (const auto& name : damaged)
    EXPECT_NE(ran.output.find("wirc-export: " + name + ": skipped ("), std::string::npos)
        << name << "\n"
        << ran.output;
  EXPECT_NE(ran.output.find(text.filename().string() + " holds no readable frame: skipped"),
            std::string::npos)
      << ran.output;
  std::vector<std::string> whole;
  size_t wholeLines = 0;
  for (size_t i = 0; i < files.size(); ++i) {
    if (i >= 1 && i <= 3) continue;
    for (auto& digest : frameDigests(files[i])) whole.push_back(digest);
    std::ifstream sidecar(fs::path(files[i]).replace_extension(".jsonl"));
    for (std::string line; std::getline(sidecar, line);) ++wholeLines;
  }
  EXPECT_EQ(frameDigests(out), whole);
  // The telemetry of the skipped segments is left out with their frames.
  EXPECT_EQ(contentsOf(out).telemetry.size(), wholeLines);
  EXPECT_NE(ran.output.find(std::to_string(whole.size()) + " frames from " +
                            std::to_string(files.size() - 3) + " segments"),
            std::string::npos)
      << ran.output;

  // Nothing readable at all: exit 1, said, and no output left behind.
  fs::path none = output("nothing-readable");
  fs::remove_all(none);
  fs::create_directories(none);
  std::ofstream(none / damaged[0], std::ios::binary) << std::string(4096, '\0');
  fs::path nothing = output("nothing.mkv");
  auto refused =
      runCommand("timeout 30 " +
                 exportCommand(none, *camera_, "--format mkv --out '" + nothing.string() + "'"));
  EXPECT_EQ(refused.exitCode, 1) << refused.output;
  EXPECT_FALSE(fs::exists(nothing));
}

TEST_F(Export, ASegmentWhoseLastBlocksAreZerosEndsAtItsLastWholeFrame) {
  fs::path copy = output("zeroed");
  fs::remove_all(copy);
  fs::copy(recorder_->out(), copy);
  auto files = recorder_->files(".mkv");
  // A power loss: the second half of the longest file's blocks written as
  // zeros.
  auto longest = *std::max_element(files.begin(), files.end(), [](const auto& a, const auto& b) {
    return fs::file_size(a) < fs::file_size(b);
  });
  fs::path zeroed = copy / longest.filename();
  auto size = fs::file_size(zeroed);
  {
    std::fstream file(zeroed, std::ios::binary | std::ios::in | std::ios::out);
    file.seekp(static_cast<std::streamoff>(size / 2));
    file << std::string(size - size / 2, '\0');
  }
  fs::path out = output("zeroed.mkv");
  auto ran = runCommand("timeout 30 " +
                        exportCommand(copy, *camera_, "--format mkv --out '" + out.string() + "'"));
  ASSERT_EQ(ran.exitCode, 0) << ran.output;
  EXPECT_NE(ran.output.find(longest.filename().string() + ": broken off after "), std::string::npos)
      << ran.output;
  EXPECT_NE(ran.output.find("a JPEG frame without its end marker"), std::string::npos)
      << ran.output;
  // No frame of zeros reaches the export: every one decodes.
  EXPECT_EQ(ffmpegDecodeErrors(out), "");
  EXPECT_LT(frameDigests(out).size(), recordedDigests().size());
}

TEST_F(Export, ACutSegmentIsSaidToEndMidFrame) {
  fs::path copy = output("cut");
  fs::remove_all(copy);
  fs::copy(recorder_->out(), copy);
  auto files = recorder_->files(".mkv");
  fs::path cut = copy / files[1].filename();
  fs::resize_file(cut, fs::file_size(cut) / 2);
  fs::path out = output("cut.mkv");
  auto ran = runCommand("timeout 30 " +
                        exportCommand(copy, *camera_, "--format mkv --out '" + out.string() + "'"));
  ASSERT_EQ(ran.exitCode, 0) << ran.output;
  EXPECT_NE(ran.output.find(files[1].filename().string() + ": "), std::string::npos) << ran.output;
  EXPECT_NE(ran.output.find(" whole frames; the file ends mid-frame"), std::string::npos)
      << ran.output;
}

TEST_F(Export, SigintStopsAnExportAndLeavesNoFileBehind) {
  // A folder of a thousand links to one segment: long enough to be stopped.
  fs::path many = output("many");
  fs::remove_all(many);
  fs::create_directories(many);
  auto files = recorder_->files(".mkv");
  std::string stem = files[0].stem().string();
  for (int i = 2; i < 1000; ++i)
    fs::create_hard_link(files[0], many / (stem + "_" + std::to_string(i) + ".mkv"));
  fs::path out = output("stopped.mkv"), said = output("stopped.txt");
  // An earlier export under the same name stays as it was.
  std::ofstream(out) << "the earlier export";
  std::ofstream(fs::path(out).replace_extension(".jsonl")) << "its telemetry";
  std::string command = "exec " +
                        exportCommand(many, *camera_, "--format mkv --out '" + out.string() + "'") +
                        " > '" + said.string() + "' 2>&1";
  pid_t exporter = fork();
  if (exporter == 0) {
    execl("/bin/sh", "sh", "-c", command.c_str(), nullptr);
    _exit(127);
  }
  fs::path partial = out.string() + ".partial";
  ASSERT_TRUE(waitFor([&] { return fs::exists(partial); }, milliseconds(30000)));
  kill(exporter, SIGINT);
  int status = 0;
  ASSERT_TRUE(
      waitFor([&] { return waitpid(exporter, &status, WNOHANG) == exporter; }, milliseconds(3000)));
  std::string output = contentsOfFile(said);
  ASSERT_TRUE(WIFEXITED(status)) << output;
  EXPECT_EQ(WEXITSTATUS(status), 1) << output;
  EXPECT_NE(output.find("stopped"), std::string::npos) << output;
  EXPECT_FALSE(fs::exists(partial));
  EXPECT_EQ(contentsOfFile(out), "the earlier export");
  EXPECT_EQ(contentsOfFile(fs::path(out).replace_extension(".jsonl")), "its telemetry");
}

TEST_F(Export, ASegmentMissingFromTheIndexIsReadBackUnlessItIsBeingWritten) {
  fs::path copy = output("unindexed");
  fs::remove_all(copy);
  fs::copy(recorder_->out(), copy);
  auto files = recorder_->files(".mkv");
  // A recorder killed before it indexed its last file, long ago.
  auto index = nlohmann::json::parse(std::ifstream(copy / "index.json"));
  auto& entries = index["segments"];
  std::string dropped = entries.back()["file"];
  entries.erase(entries.size() - 1);
  std::ofstream(copy / "index.json") << index.dump();
  fs::last_write_time(copy / dropped, fs::file_time_type::clock::now() - std::chrono::hours(1));
  fs::path out = output("unindexed.mkv");
  auto ran = runCommand(exportCommand(copy, *camera_, "--format mkv --out '" + out.string() + "'"));
  ASSERT_EQ(ran.exitCode, 0) << ran.output;
  EXPECT_NE(ran.output.find(dropped + " is not in index.json: read back and exported"),
            std::string::npos)
      << ran.output;
  EXPECT_EQ(frameDigests(out).size(), recordedDigests().size());
  // Written to just now: the one a recorder is writing.
  fs::last_write_time(copy / dropped, fs::file_time_type::clock::now());
  auto open =
      runCommand(exportCommand(copy, *camera_, "--format mkv --out '" + out.string() + "'"));
  EXPECT_NE(open.output.find(dropped + " is still being written: not exported"), std::string::npos)
      << open.output;
}

}  // namespace
