// A reload as users make one (SIGHUP, POST /api/config/reload) while four
// cameras record: a camera added starts, one removed finishes its file and
// stops, one whose settings changed restarts with them, and a file that does
// not validate or changes what takes a restart is refused with nothing
// changed. The untouched cameras record on: every frame their device sent
// is in their one file, in order.
#include <gtest/gtest.h>
#include <signal.h>

#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

#include "camera_checks.h"
#include "http_fetch.h"
#include "scene_frames.h"
#include "shell_command.h"
#include "simulated_device.h"
#include "wait_for.h"

namespace {

namespace fs = std::filesystem;
using namespace wircam::testing;
using namespace std::chrono_literals;

constexpr char kToken[] = "reload-test-token-0123456789";
const Headers kAuthorized = {{"Authorization", std::string("Bearer ") + kToken}};

// The config file the recorder reads: a [recorder] group and one
// [device NAME] per vehicle, rewritten for each reload.
class ConfigFile {
 public:
  explicit ConfigFile(fs::path path) : path_(std::move(path)) {}
  const fs::path& path() const { return path_; }
  void write(const std::string& recorder, const std::map<std::string, uint16_t>& devices) {
    std::ofstream file(path_);
    file << "[recorder]\n" << recorder;
    for (const auto& [name, port] : devices)
      file << "[device " << name << "]\nhost=127.0.0.1\nport=" << port << "\n";
  }

 private:
  fs::path path_;
};

// Where each recorded frame sits in the scene's sequence (each camera sees
// the whole sequence from its first frame, in order).
std::vector<size_t> sequenceOf(const std::vector<std::string>& digests) {
  static const std::map<std::string, size_t> index = [] {
    std::map<std::string, size_t> positions;
    const auto& frames = sceneFrames();
    for (size_t i = 0; i < frames.size(); ++i) {
      gchar* md5 = g_compute_checksum_for_data(G_CHECKSUM_MD5, frames[i].data(), frames[i].size());
      positions[md5] = i;
      g_free(md5);
    }
    return positions;
  }();
  std::vector<size_t> sequence;
  for (const auto& digest : digests) {
    auto found = index.find(digest);
    sequence.push_back(found == index.end() ? SIZE_MAX : found->second);
  }
  return sequence;
}

// The frames missing between the recorded ones (none: not one frame period
// without its frame), or SIZE_MAX for a frame the scene never sent.
size_t framesMissing(const std::vector<size_t>& sequence) {
  size_t missing = 0, cycle = sceneFrames().size();
  for (size_t i = 1; i < sequence.size(); ++i) {
    if (sequence[i] == SIZE_MAX || sequence[i - 1] == SIZE_MAX) return SIZE_MAX;
    missing += (sequence[i] + cycle - sequence[i - 1] - 1) % cycle;
  }
  return missing;
}

TEST(ConfigReload, CamerasComeGoAndRestartAloneWhileTheOthersRecordEveryFrame) {
  std::map<std::string, std::unique_ptr<wircam::wirc::Device>> devices;
  for (const char* name : {"a", "b", "c", "d", "e", "f"}) {
    devices[name] = startSequenceDevice();
    ASSERT_TRUE(devices[name]);
  }
  auto port = [&](const char* name) { return devices[name]->port(); };
  fs::path folder = fs::temp_directory_path() / ("wircam-reload-" + std::to_string(getpid()));
  fs::remove_all(folder);
  fs::create_directories(folder);
  fs::path out = folder / "out";
  ConfigFile config(folder / "recorder.ini");
  std::string recorderGroup = "out=" + out.string() + "\nsegment=600\n";
  std::map<std::string, uint16_t> recorded = {
      {"a", port("a")}, {"b", port("b")}, {"c", port("c")}, {"d", port("d")}};
  config.write(recorderGroup, recorded);
  // With every server whose cameras come and go: the web's, RTSP's and
  // Foxglove's (a removed camera's RTSP mount once crashed the stop).
  RecorderProcess recorder(0, {"--config", config.path(), "--http", "127.0.0.1:0", "--http-token",
                               kToken, "--rtsp", "127.0.0.1:0", "--foxglove", "127.0.0.1:0"});
  auto url = recorder.waitForLog("http://", 5000ms);
  ASSERT_TRUE(url) << recorder.log();
  auto rtsp = recorder.waitForLog("rtsp://", 5000ms);
  ASSERT_TRUE(rtsp) << recorder.log();
  std::string rtspServer = rtsp->substr(0, rtsp->find('/', 7));  // rtsp://HOST:PORT
  // Five frames of a camera's RTSP mount, as a client we did not write.
  // The client says what it did (rtspsrc's steps, every warning): once in
  // five runs beside two busy loops it got no frame in 40 s, and said
  // nothing.
  auto playRtsp = [&](const std::string& path) {
    return runCommand(
        "GST_DEBUG=2,rtspsrc:4 timeout 40 gst-launch-1.0 -q rtspsrc "
        "location='rtsp://viewer:" +
        std::string(kToken) + "@" + rtspServer.substr(7) + path +
        "' protocols=tcp ! rtpjpegdepay ! jpegdec ! fakesink num-buffers=5 2>&1");
  };
  for (const char* camera : {"a-cam0", "b-cam0", "c-cam0", "d-cam0"})
    ASSERT_TRUE(waitFor([&] { return framesOf(*url, camera, kAuthorized) > 5; }, 10s))
        << camera << "\n"
        << recorder.log();
  // The cameras named have each recorded `frames` more since called: the
  // reloads are spread over the recording, not bunched at its start.
  auto progress = [&](std::vector<std::string> cameras, uint64_t frames = 10) {
    std::map<std::string, uint64_t> from;
    for (const auto& camera : cameras) from[camera] = framesOf(*url, camera, kAuthorized);
    for (const auto& camera : cameras)
      ASSERT_TRUE(waitFor(
          [&] { return framesOf(*url, camera, kAuthorized) >= from[camera] + frames; }, 10s))
          << camera << "\n"
          << recorder.log();
  };
  auto reload = [&] { return fetch(*url + "api/config/reload", "POST", kAuthorized); };

  // 1. SIGHUP, a device added: its camera starts; nobody else is touched.
  recorded["e"] = port("e");
  config.write(recorderGroup, recorded);
  recorder.signal(SIGHUP);
  ASSERT_TRUE(recorder.waitForText("reloaded: 1 camera(s) added, 0 removed, 0 restarted", 5s))
      << recorder.log();
  progress({"a-cam0", "e-cam0"});
  auto added = playRtsp("/e/cam0");
  EXPECT_EQ(added.exitCode, 0) << added.output;

  // 2. Device d moved to another vehicle: d-cam0 alone restarts, with it.
  recorded["d"] = port("f");
  config.write(recorderGroup, recorded);
  auto moved = reload();
  ASSERT_EQ(moved.status, 200u) << moved.body;
  auto changes = nlohmann::json::parse(moved.body);
  EXPECT_EQ(changes["restarted"], nlohmann::json::array({"d-cam0"})) << moved.body;
  EXPECT_EQ(changes["unchanged"].size(), 4u) << moved.body;
  ASSERT_TRUE(recorder.waitForText(
      "d-cam0: link live: logged in to 127.0.0.1:" + std::to_string(port("f")), 10s))
      << recorder.log();
  progress({"a-cam0", "d-cam0"});

  // 3. Device e removed: its file is finished and indexed, its camera gone.
  recorded.erase("e");
  config.write(recorderGroup, recorded);
  auto removed = reload();
  ASSERT_EQ(removed.status, 200u) << removed.body;
  EXPECT_EQ(nlohmann::json::parse(removed.body)["removed"], nlohmann::json::array({"e-cam0"}));
  ASSERT_TRUE(waitFor([&] { return indexedFrames(out, "e-cam0") > 5; }, 5s)) << recorder.log();
  // Gone from the API once it has ended (just after its file is indexed).
  EXPECT_TRUE(waitFor([&] { return cameraEntry(*url, "e-cam0", kAuthorized).is_null(); }, 5s));
  auto gone = playRtsp("/e/cam0");
  EXPECT_NE(gone.exitCode, 0);
  EXPECT_NE(gone.output.find("Not Found"), std::string::npos) << gone.output;
  progress({"a-cam0"});

  // 4. A value that does not validate: 400 with the reason, nothing changed.
  config.write(recorderGroup + "stall-timeout=0.1\n", recorded);
  auto invalid = reload();
  EXPECT_EQ(invalid.status, 400u);
  EXPECT_NE(invalid.body.find("stall-timeout: seconds, 0.5..3600"), std::string::npos)
      << invalid.body;

  // 5. SIGHUP with another --out: that takes a restart; refused, said why.
  config.write("out=" + (folder / "elsewhere").string() + "\nsegment=600\n", recorded);
  recorder.signal(SIGHUP);
  EXPECT_TRUE(recorder.waitForText("reload refused: out changed", 5s)) << recorder.log();
  progress({"a-cam0"});

  // What was refused changed nothing: the file as it was, nothing to do.
  config.write(recorderGroup, recorded);
  auto same = reload();
  ASSERT_EQ(same.status, 200u) << same.body;
  EXPECT_EQ(nlohmann::json::parse(same.body)["unchanged"].size(), 4u) << same.body;
  EXPECT_TRUE(nlohmann::json::parse(same.body)["restarted"].empty()) << same.body;
  progress({"a-cam0", "b-cam0", "c-cam0", "d-cam0"});

  expectSigintEndsItWithinThreeSeconds(recorder);
  auto filesOf = [&](const std::string& camera) {
    std::vector<fs::path> files;
    for (const auto& entry : fs::directory_iterator(out))
      if (entry.path().extension() == ".mkv" &&
          entry.path().filename().string().starts_with(camera))
        files.push_back(entry.path());
    std::sort(files.begin(), files.end());
    return files;
  };
  // The untouched cameras: one file each, every frame from their first on.
  for (const char* camera : {"a-cam0", "b-cam0", "c-cam0"}) {
    auto files = filesOf(camera);
    ASSERT_EQ(files.size(), 1u) << camera << " was cut by a reload\n" << recorder.log();
    auto sequence = sequenceOf(frameDigests(files[0]));
    EXPECT_GE(sequence.size(), 50u) << camera;
    EXPECT_EQ(framesMissing(sequence), 0u) << camera << ": frames missing across the reloads";
  }
  // The moved camera: a file before the move and one after.
  EXPECT_GE(filesOf("d-cam0").size(), 2u) << recorder.log();
  EXPECT_EQ(filesOf("e-cam0").size(), 1u) << recorder.log();
  fs::remove_all(folder);
}

TEST(ConfigReload, WithoutAConfigFileThereIsNothingToReadAgainAndItSaysSo) {
  auto device = startSequenceDevice();
  ASSERT_TRUE(device);
  RecorderProcess recorder(device->port(), {"--http", "127.0.0.1:0", "--http-token", kToken});
  auto url = recorder.waitForLog("http://", 5000ms);
  ASSERT_TRUE(url) << recorder.log();
  auto answer = fetch(*url + "api/config/reload", "POST", kAuthorized);
  EXPECT_EQ(answer.status, 400u) << answer.body;
  EXPECT_NE(answer.body.find("started without --config"), std::string::npos) << answer.body;
  recorder.signal(SIGHUP);
  EXPECT_TRUE(recorder.waitForText("reload refused: there is no config file", 5s))
      << recorder.log();
  EXPECT_TRUE(recorder.waitForText("live", 5s)) << recorder.log();  // and it records on
}

}  // namespace
