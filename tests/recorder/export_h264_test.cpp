// wirc-export of H.264 recordings (--codec h264), read back by others'
// readers (ffprobe, ffmpeg, and for MCAP @mcap/core under node).
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "camera_checks.h"
#include "export_command.h"
#include "recorder_process.h"
#include "shell_command.h"
#include "simulated_device.h"

namespace {

namespace fs = std::filesystem;
using namespace wircam;
using namespace wircam::testing;

// H.264 stays H.264: a recording transcoded by the recorder (--codec h264,
// MP4 segments) exports to MP4, Matroska and MCAP with its frames as they
// were stored, starting on a key frame.
TEST(ExportH264, EveryFormatCarriesTheRecordedH264Untouched) {
  auto device = startSequenceDevice();
  RecorderProcess recorder(
      device->port(), {"--segment", "2", "--duration", "7", "--codec", "h264", "--format", "mp4"});
  ASSERT_EQ(recorder.wait(), 0) << recorder.log();
  std::vector<std::string> recorded;
  for (const auto& file : recorder.files(".mp4"))
    for (auto& digest : frameDigests(file)) recorded.push_back(digest);
  ASSERT_GT(recorded.size(), 60u);
  std::string camera = cameraName(device->port());
  for (const char* format : {"mp4", "mkv"}) {
    // To a file, and streamed (as GET /api/export sends it: MP4 in
    // fragments, Matroska without its index): the same frames, the
    // telemetry track not shown.
    for (bool streamed : {false, true}) {
      fs::path out = recorder.out().parent_path() /
                     ((streamed ? "h264-streamed." : "h264.") + std::string(format));
      std::string to =
          streamed ? " --out - > '" + out.string() + "'; }" : " --out '" + out.string() + "'";
      // (Braced: runCommand's 2>&1 then takes the messages, not the file.)
      auto ran =
          runCommand((streamed ? "{ " : "") +
                     exportCommand(recorder.out(), camera, std::string("--format ") + format + to));
      ASSERT_EQ(ran.exitCode, 0) << ran.output;
      EXPECT_EQ(frameDigests(out), recorded) << out;
      EXPECT_EQ(ffmpegDecodeErrors(out), "") << out;
      EXPECT_EQ(
          runCommand("ffprobe -v error -show_entries stream=codec_name:stream_disposition=default "
                     "-of csv=p=0 '" +
                     out.string() + "'")
              .output,
          "h264,1\n" + std::string(format == std::string("mp4") ? "mov_text" : "subrip") + ",0\n")
          << out;
    }
  }
  fs::path mcap = recorder.out().parent_path() / "h264.mcap";
  ASSERT_EQ(runCommand(exportCommand(recorder.out(), camera,
                                     "--format mcap --out '" + mcap.string() + "'"))
                .exitCode,
            0);
  // Foxglove decodes H.264 as Annex B, each key frame with its SPS and
  // PPS: the images alone, one after the other, are a stream ffmpeg reads.
  fs::path stream = recorder.out().parent_path() / "h264-images.h264";
  auto checked = runCommand("node '" MCAP_CHECK_DIR "/check.mjs' '" + mcap.string() +
                            "' --images-to '" + stream.string() + "'");
  ASSERT_EQ(checked.exitCode, 0) << checked.output;
  auto result = nlohmann::json::parse(checked.output);
  EXPECT_EQ(result["invalid"], nlohmann::json::array()) << result["invalid"];
  for (const auto& image : result["images"]) EXPECT_EQ(image["format"], "h264");
  EXPECT_EQ(result["images"].size(), recorded.size());
  EXPECT_EQ(ffmpegDecodeErrors(stream), "");
  EXPECT_EQ(decodedFrameCount(stream), std::to_string(recorded.size()) + "\n");
}

// A range that starts between key frames starts on the next IDR, decided
// from the bitstream: matroskademux flags no H.264 frame as a delta, and
// the export began on frames no decoder could use (5 of 32 undecodable).
TEST(ExportH264, ARangeStartingBetweenKeyFramesStartsOnAnIdrAndEveryFrameDecodes) {
  auto device = startSequenceDevice();
  RecorderProcess recorder(device->port(),
                           {"--segment", "2", "--duration", "5", "--codec", "h264"});
  ASSERT_EQ(recorder.wait(), 0) << recorder.log();
  auto index = nlohmann::json::parse(std::ifstream(recorder.out() / "index.json"))["segments"];
  ASSERT_GE(index.size(), 2u);
  // 200 ms into the second segment: past its first key frame, before the
  // next (one each 0.5 s).
  std::string start = shiftedIso(index[1]["start_utc"], 200);
  fs::path out = recorder.out().parent_path() / "mid-gop.mkv";
  auto ran =
      runCommand(exportCommand(recorder.out(), cameraName(device->port()),
                               "--start " + start + " --format mkv --out '" + out.string() + "'"));
  ASSERT_EQ(ran.exitCode, 0) << ran.output;
  auto first = runCommand(
      "ffprobe -v error -select_streams v:0 -read_intervals %+#1 "
      "-show_entries frame=key_frame,pict_type -of csv=p=0 '" +
      out.string() + "'");
  EXPECT_EQ(first.output, "1,I\n") << ran.output;
  // "wirc-export: FILE: 36 frames from 2 segments, ...": each one decodes.
  auto said = ran.output.find(" frames from ");
  ASSERT_NE(said, std::string::npos) << ran.output;
  auto count = ran.output.substr(ran.output.rfind(' ', said - 1) + 1,
                                 said - ran.output.rfind(' ', said - 1) - 1);
  EXPECT_EQ(decodedFrameCount(out), count + "\n") << ran.output;
  EXPECT_EQ(ffmpegDecodeErrors(out), "");
}

}  // namespace
