// The recorder's pipeline for each codec/container pair and option, as
// parsed from a command line: what it names, what it holds, what it must not.
#include "app/pipeline_planner.h"

#include <gtest/gtest.h>

#include <initializer_list>
#include <set>

namespace {

using namespace wircam::recorder;

RecorderOptions optionsOf(std::initializer_list<const char*> args) {
  std::vector<char*> argv{const_cast<char*>("wirc-recorder")};
  for (const char* a : args) argv.push_back(const_cast<char*>(a));
  auto options = parseOptions(static_cast<int>(argv.size()), argv.data());
  EXPECT_TRUE(options) << (options ? "" : options.error());
  return options ? *options : RecorderOptions{};
}

bool has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST(PipelinePlan, JpegInMatroskaIsMuxedUntouchedWithItsTelemetryTrack) {
  auto plan = planPipeline(optionsOf({"--device", "10.0.0.2", "--out", "/rec"}));
  ASSERT_EQ(plan.streams.size(), 1u);
  const auto& s = plan.streams[0];
  EXPECT_EQ(s.name, "10.0.0.2-cam0");
  EXPECT_FALSE(plan.transcoded);
  const auto& d = plan.description();
  EXPECT_TRUE(has(d, "wircsrc name=" + s.source + " host=10.0.0.2 port=1984"));
  EXPECT_TRUE(has(d, "wait-for-device=true"));
  // From the source to the muxer, text track and all, no queue and no tee
  // (the SegmentWriter puts each file in): the disk's thread writes the
  // bytes, within 8 MB. One thread a camera.
  EXPECT_EQ(s.videoTail, s.source);
  EXPECT_FALSE(has(d, "queue"));
  EXPECT_EQ(s.recordBound, 8'000'000u);
  EXPECT_FALSE(has(d, "tee"));
  EXPECT_FALSE(has(d, "splitmuxsink"));
  EXPECT_EQ(s.muxer.factory, "matroskamux");
  EXPECT_TRUE(s.muxer.text);
  EXPECT_TRUE(s.telemetrySource.empty());  // fed on the frames' thread
  EXPECT_FALSE(has(d, "appsrc"));
  EXPECT_TRUE(has(d, "taginject name=" + s.telemetryTail));
  EXPECT_TRUE(has(d, "title=telemetry-json-lines"));  // renamed when finished
  EXPECT_FALSE(has(d, "x264enc"));
  EXPECT_TRUE(s.detector.empty() && s.controller.empty() && s.liveSink.empty());
}

TEST(PipelinePlan, H264InMp4IsTranscodedAndKeepsTheTextTrack) {
  auto plan = planPipeline(
      optionsOf({"--device", "rover", "--out", "/rec", "--codec", "h264", "--format", "mp4"}));
  EXPECT_TRUE(plan.transcoded);
  EXPECT_TRUE(has(plan.description(), "x264enc"));
  // Frames are planned (or dropped for the disk) before they are decoded.
  EXPECT_TRUE(has(plan.description(), "tjpegdec name=" + plan.streams[0].planPoint + " !"));
  EXPECT_EQ(plan.streams[0].muxer.factory, "mp4mux");
  // mp4mux takes its text from an appsrc's thread.
  EXPECT_TRUE(has(plan.description(), "appsrc name=" + plan.streams[0].telemetrySource));
  EXPECT_TRUE(has(plan.description(), "title=telemetry\""));
  // The muxers take H.264 as avc only: the encoder's output says so.
  EXPECT_TRUE(has(plan.description(), "capsfilter name=" + plan.streams[0].videoTail +
                                          " caps=\"video/x-h264,stream-format=avc"));
}

TEST(PipelinePlan, WithoutTheTelemetryTrackAStreamIsItsSourceAlone) {
  auto plan = planPipeline(
      optionsOf({"--device", "10.0.0.2", "--out", "/rec", "--telemetry-track", "off"}));
  const auto& s = plan.streams[0];
  EXPECT_FALSE(s.muxer.text);
  EXPECT_TRUE(s.telemetrySource.empty() && s.telemetryTail.empty());
  EXPECT_FALSE(has(plan.description(), "appsrc"));
  EXPECT_FALSE(has(plan.description(), "taginject"));
  // From the source to the muxer, no queue, as with it.
  EXPECT_EQ(s.videoTail, s.source);
  EXPECT_EQ(s.recordBound, 8'000'000u);
  EXPECT_FALSE(has(plan.description(), "queue"));
  // --record-queue 0: the files are written on the source's thread.
  auto lean = planPipeline(optionsOf({"--device", "10.0.0.2", "--out", "/rec", "--telemetry-track",
                                      "off", "--record-queue", "0"}));
  EXPECT_EQ(lean.streams[0].videoTail, lean.streams[0].source);
  EXPECT_EQ(lean.streams[0].recordBound, 0u);
}

PipelinePlan twoFollowedDevicesOfTwoCameras() {
  return planPipeline(
      optionsOf({"--device", "a", "--device", "b", "--camera", "0", "--camera", "1", "--out",
                 "/rec", "--detect", "tag36h11", "--follow", "--http", ":0"}));
}

TEST(PipelinePlan, EachCameraIsAStreamAndOnlyTheFirstOfAFollowingDeviceSteers) {
  auto plan = twoFollowedDevicesOfTwoCameras();
  ASSERT_EQ(plan.streams.size(), 4u);
  std::set<std::string> names;
  for (const auto& s : plan.streams) {
    names.insert(s.name);
    EXPECT_FALSE(s.detector.empty());
    EXPECT_FALSE(s.liveSink.empty());
  }
  EXPECT_EQ(names.size(), 4u);
  EXPECT_FALSE(plan.streams[0].controller.empty());
  EXPECT_TRUE(plan.streams[1].controller.empty());
  // Branches: the file's frames leave the tee by a pad of their own
  // (which the SegmentWriter links to each file).
  EXPECT_EQ(plan.streams[0].videoTail, "t");
  EXPECT_FALSE(plan.streams[2].controller.empty());
  EXPECT_TRUE(has(plan.description(), "family=tag36h11"));
}

// A reload compares plans: a camera's must not change with its place.
TEST(PipelinePlan, ACamerasPlanIsTheSameWhereverItsDeviceStands) {
  auto first = planPipeline(optionsOf({"--device", "a", "--device", "b", "--out", "/rec"}));
  auto second = planPipeline(optionsOf({"--device", "b", "--out", "/rec"}));
  EXPECT_TRUE(first.streams[1] == second.streams[0]);
}

TEST(PipelinePlan, AControlUriSteersItsVehicle) {
  auto plan = planPipeline(optionsOf({"--device", "127.0.0.1:2000,control=rcoip://10.0.0.9:9000",
                                      "--out", "/rec", "--detect", "tag36h11", "--follow"}));
  EXPECT_TRUE(has(plan.description(), "protocol=rcoip host=10.0.0.9 port=9000"));
}

TEST(PipelinePlan, EachCameraIsAPipelineOfItsOwn) {
  auto plan = twoFollowedDevicesOfTwoCameras();
  ASSERT_EQ(plan.streams.size(), 4u);
  for (const auto& stream : plan.streams) {
    // Everything it names is in its own description; it records its own
    // device and camera.
    for (const auto* name : {&stream.source, &stream.telemetrySource, &stream.telemetryTail,
                             &stream.detector, &stream.liveSink}) {
      EXPECT_TRUE(has(stream.description, "name=" + *name)) << *name;
    }
    EXPECT_TRUE(has(stream.description, "host=" + stream.device + " "));
    EXPECT_TRUE(has(stream.description, "camera=" + std::to_string(stream.camera) + " "));
  }
}

}  // namespace

namespace {

TEST(PipelinePlan, OneCameraOfOneDeviceUnderTwoNamesIsRefused) {
  // [device a] and [device b] at one address: the device streams camera 0
  // to one receiver at a time, and the two took it from each other (each
  // recorded a third of the time, a stranger's trial).
  RecorderOptions options;
  options.devices = {{.host = "127.0.0.1", .port = 27103, .label = "a", .cameras = {0, 1}},
                     {.host = "127.0.0.1", .port = 27103, .label = "b", .cameras = {0}}};
  auto problem = cameraRecordedTwice(options);
  ASSERT_TRUE(problem);
  EXPECT_EQ(problem->rfind("'a' and 'b' both record camera 0 of 127.0.0.1:27103", 0), 0u)
      << *problem;
  // Other cameras of it, or the same camera of another device, are fine.
  options.devices[1].cameras = {2};
  EXPECT_EQ(cameraRecordedTwice(options), std::nullopt);
  options.devices[1] = {.host = "127.0.0.1", .port = 27104, .label = "b", .cameras = {0}};
  EXPECT_EQ(cameraRecordedTwice(options), std::nullopt);
}

}  // namespace
