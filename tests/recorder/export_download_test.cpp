// GET /api/export on a recorder that is still recording (the simulated car
// following its tag): the file comes streamed (chunked) through a real HTTP
// client, holds exactly the finished segments' frames, says what it left
// out, and writes nothing to disk; as MCAP its detections are image
// annotations.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "camera_checks.h"
#include "http_fetch.h"
#include "recorder_process.h"
#include "shell_command.h"
#include "signed_in_page.h"
#include "wait_for.h"

namespace {

namespace fs = std::filesystem;
using namespace wircam;
using namespace wircam::testing;
using std::chrono::milliseconds;

// A live recorder with 2 s segments and the web server, for every test.
class ExportDownload : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    car_ = new FollowedCar;
    recorder_ = new RecorderProcess(
        car_->device->port(),
        {"--detect", "tag36h11", "--segment", "2", "--http", "127.0.0.1:0", "--duration", "90"});
    url_ = new std::string(recorder_->waitForLog("http://", milliseconds(10000)).value_or(""));
    camera_ = new std::string(cameraName(car_->device->port()));
    ASSERT_TRUE(waitFor(
        [] { return indexedFrames(recorder_->out(), *camera_) > 0 && segments().size() >= 2; },
        milliseconds(15000)))
        << recorder_->log();
  }
  static void TearDownTestSuite() {
    delete recorder_;
    delete car_;
    delete url_;
    delete camera_;
  }

  static nlohmann::json segments() {
    std::ifstream index(recorder_->out() / "index.json");
    auto json = nlohmann::json::parse(index, nullptr, false);
    return json.is_object() ? json.value("segments", nlohmann::json::array())
                            : nlohmann::json::array();
  }
  static std::string exportUrl(const std::string& query) { return *url_ + "api/export?" + query; }
  // The body, kept as a file to read back.
  static fs::path saved(const Response& response, const std::string& name) {
    fs::path file = recorder_->out().parent_path() / name;
    std::ofstream(file, std::ios::binary) << response.body;
    return file;
  }

  static FollowedCar* car_;
  static RecorderProcess* recorder_;
  static std::string* url_;
  static std::string* camera_;
};
FollowedCar* ExportDownload::car_ = nullptr;
RecorderProcess* ExportDownload::recorder_ = nullptr;
std::string* ExportDownload::url_ = nullptr;
std::string* ExportDownload::camera_ = nullptr;

TEST_F(ExportDownload, AllOfItIsTheFinishedSegmentsFramesUntouchedAsAFileToSave) {
  auto response = fetch(exportUrl("camera=" + *camera_ + "&format=mkv"));
  ASSERT_EQ(response.status, 200u) << response.body.substr(0, 300);
  EXPECT_EQ(response.contentType, "video/x-matroska");
  EXPECT_EQ(response.headers["transfer-encoding"], "chunked");
  EXPECT_EQ(response.headers.count("content-length"), 0u);
  auto disposition = response.headers["content-disposition"];
  EXPECT_EQ(disposition.find("attachment; filename=\"" + *camera_ + "_"), 0u) << disposition;
  EXPECT_TRUE(disposition.ends_with(".mkv\"")) << disposition;
  // The segment being written is left out, and the client is told.
  EXPECT_NE(response.headers["x-export-notes"].find("is still being written: not exported"),
            std::string::npos)
      << response.headers["x-export-notes"];

  fs::path file = saved(response, "download.mkv");
  auto exported = frameDigests(file);
  ASSERT_FALSE(exported.empty());
  // Whole finished segments, from the first: every frame, byte for byte.
  std::vector<std::string> recorded;
  for (const auto& segment : segments()) {
    if (recorded.size() >= exported.size()) break;
    for (auto& digest : frameDigests(recorder_->out() / segment["file"].get<std::string>()))
      recorded.push_back(digest);
  }
  EXPECT_EQ(exported, recorded);
  EXPECT_EQ(ffmpegDecodeErrors(file), "");
}

TEST_F(ExportDownload, ARangeWithAnOffsetAsTypedInTheAddressBarComesAsMcapWithTheTags) {
  auto first = segments().at(0);
  // "+00:00" unescaped: a query's '+' reads as a space, and is given back.
  std::string start = first["start_utc"].get<std::string>();
  ASSERT_TRUE(start.ends_with("Z")) << start;
  start = start.substr(0, start.size() - 1) + "+00:00";
  auto single =
      fetch(exportUrl("camera=" + *camera_ + "&start=" + start + "&end=" + start + "&format=mcap"));
  ASSERT_EQ(single.status, 200u) << single.body.substr(0, 300);
  EXPECT_TRUE(single.headers["content-disposition"].ends_with(".mcap\""));
  fs::path one = saved(single, "single.mcap");
  auto checkedOne = runCommand("node '" MCAP_CHECK_DIR "/check.mjs' '" + one.string() + "'");
  ASSERT_EQ(checkedOne.exitCode, 0) << checkedOne.output;
  EXPECT_EQ(nlohmann::json::parse(checkedOne.output)["images"].size(), 1u);

  // The first segment, read by @mcap/core: the frames with a tag have their
  // outlines on /tags, valid against Foxglove's schema.
  std::string end = segments().at(1)["start_utc"];
  auto segment =
      fetch(exportUrl("camera=" + *camera_ + "&start=" + start + "&end=" + end + "&format=mcap"));
  ASSERT_EQ(segment.status, 200u) << segment.body.substr(0, 300);
  fs::path file = saved(segment, "download.mcap");
  auto checked = runCommand("node '" MCAP_CHECK_DIR "/check.mjs' '" + file.string() + "'");
  ASSERT_EQ(checked.exitCode, 0) << checked.output;
  auto result = nlohmann::json::parse(checked.output);
  EXPECT_EQ(result["invalid"], nlohmann::json::array()) << result["invalid"];
  EXPECT_GT(result["topics"]["/" + *camera_ + "/tags"].get<int>(), 5) << result["topics"];
  // Decoded with Foxglove's protobuf definitions: an outline per tag seen,
  // stamped with its frame's time.
  EXPECT_EQ(result["encodings"]["/" + *camera_ + "/tags"], "protobuf");
  EXPECT_GT(result["outlines"].get<int>(), 5);
  EXPECT_EQ(result["annotationsOffTheirTime"], 0);
  // The first segment's frames (and the second's first, if it came at the
  // range's end to the millisecond).
  auto frames = result["topics"]["/" + *camera_ + "/image"].get<size_t>();
  size_t firstSegment = frameDigests(recorder_->out() / first["file"].get<std::string>()).size();
  EXPECT_GE(frames, firstSegment);
  EXPECT_LE(frames, firstSegment + 1);
}

TEST_F(ExportDownload, WrongRequestsAreAnsweredInJson) {
  auto expectError = [](const std::string& query, guint status, const std::string& says) {
    auto response = fetch(exportUrl(query));
    EXPECT_EQ(response.status, status) << query;
    EXPECT_EQ(response.contentType, "application/json") << query;
    auto json = nlohmann::json::parse(response.body, nullptr, false);
    ASSERT_TRUE(json.is_object()) << response.body;
    EXPECT_NE(json.value("error", "").find(says), std::string::npos) << response.body;
  };
  expectError("camera=nobody-cam9&format=mkv", 404, "no camera nobody-cam9");
  expectError("camera=" + *camera_ + "&format=avi", 400, "format= is mkv, mp4 or mcap");
  expectError("format=mkv", 400, "camera= is needed");
  expectError("camera=" + *camera_ + "&format=mkv&start=yesterday", 400,
              "start= 'yesterday' is not an ISO 8601 time");
  expectError(
      "camera=" + *camera_ + "&format=mkv&start=2026-01-02T00:00:00Z&end=2026-01-01T00:00:00Z", 400,
      "end= is before start=");
  expectError(
      "camera=" + *camera_ + "&format=mkv&start=2001-01-01T00:00:00Z&end=2001-01-01T00:01:00Z", 404,
      "has no frame in that range");
  // JPEG recordings cannot go into MP4 (its muxer takes no JPEG): said, not written.
  expectError("camera=" + *camera_ + "&format=mp4", 415, "mp4 needs H.264 recordings");
}

TEST_F(ExportDownload, NothingIsWrittenToDiskForADownload) {
  auto response = fetch(exportUrl("camera=" + *camera_ + "&format=mkv"));
  ASSERT_EQ(response.status, 200u);
  // Streamed from the export to the client: no file of its own (versions
  // before wrote it whole into .exports first).
  for (const auto& entry : fs::directory_iterator(recorder_->out())) {
    auto extension = entry.path().extension();
    EXPECT_TRUE(extension == ".mkv" || extension == ".jsonl" || extension == ".json")
        << entry.path();
  }
  // Not a recording either: the list does not show the folder.
  auto list = nlohmann::json::parse(fetch(*url_ + "recordings").body);
  for (const auto& file : list) EXPECT_FALSE(file["name"].get<std::string>().starts_with("."));
}

}  // namespace

TEST_F(ExportDownload, AClientThatLeavesLeavesNothingBehind) {
  // The request sent, the connection closed before the answer.
  GUri* uri = g_uri_parse(url_->c_str(), G_URI_FLAGS_NONE, nullptr);
  ASSERT_TRUE(uri);
  GSocketClient* client = g_socket_client_new();
  GSocketConnection* connection = g_socket_client_connect_to_host(
      client, "127.0.0.1", static_cast<guint16>(g_uri_get_port(uri)), nullptr, nullptr);
  g_uri_unref(uri);
  ASSERT_TRUE(connection);
  std::string request =
      "GET /api/export?camera=" + *camera_ + "&format=mcap HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n";
  EXPECT_TRUE(g_output_stream_write_all(g_io_stream_get_output_stream(G_IO_STREAM(connection)),
                                        request.data(), request.size(), nullptr, nullptr, nullptr));
  g_io_stream_close(G_IO_STREAM(connection), nullptr, nullptr);
  g_object_unref(connection);
  g_object_unref(client);

  // Stopped, or written and not sent: either way said, and the file gone.
  EXPECT_TRUE(waitFor(
      [] {
        auto log = recorder_->log();
        return log.find("export of " + *camera_ + " (mcap): stopped, the client left") !=
                   std::string::npos ||
               log.find("export of " + *camera_ + " (mcap): the client left before") !=
                   std::string::npos;
      },
      milliseconds(10000)))
      << recorder_->log();
  EXPECT_FALSE(fs::exists(recorder_->out() / ".exports"));
  EXPECT_EQ(fetch(*url_ + "api/status").status, 200u);
}

// Last, as it damages the recording: a finished segment turned to zeros
// (what a power loss can leave). Exports go on answering, each leaving it
// out and saying so, and hold no export slot (two) for ever.
TEST_F(ExportDownload, ASegmentOfZerosIsLeftOutAndSaidAndHoldsNoExportSlot) {
  auto index = segments();
  ASSERT_GE(index.size(), 2u);
  std::string damaged = index[0]["file"];
  std::ofstream(recorder_->out() / damaged, std::ios::binary | std::ios::trunc)
      << std::string(64 * 1024, '\0');
  for (int i = 0; i < 3; ++i) {
    auto response = fetch(exportUrl("camera=" + *camera_ + "&format=mkv"));
    ASSERT_EQ(response.status, 200u) << i << ": " << response.body.substr(0, 300);
    EXPECT_NE(response.headers["x-export-notes"].find(damaged + ": skipped ("), std::string::npos)
        << response.headers["x-export-notes"];
  }
}
