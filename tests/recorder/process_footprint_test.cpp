// What a running wirc-recorder holds beside its cameras: libraries it was
// not asked to use are not loaded (libmosquitto brings OpenSSL, 1.8 MB
// resident; the web and RTSP servers libsoup, krb5, sqlite and more, about
// 3 MB), and GLib's per-thread slice caches are off.
#include <glib.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "mqtt_broker.h"
#include "recorder_process.h"
#include "shell_command.h"
#include "simulated_device.h"

namespace {

using namespace wircam::testing;
using namespace std::chrono_literals;
namespace fs = std::filesystem;

std::string procFile(pid_t pid, const char* name) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/" + name);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

bool maps(const RecorderProcess& recorder, const std::string& library) {
  return procFile(recorder.pid(), "maps").find(library) != std::string::npos;
}

TEST(RecorderFootprint, LoadsLibmosquittoAndOpenSslOnlyForMqtt) {
  auto device = startSequenceDevice();
  ASSERT_TRUE(device);
  RecorderProcess plain(device->port(), {"--duration", "30"});
  ASSERT_TRUE(plain.waitForText(": live", 10s)) << plain.log();
  EXPECT_FALSE(maps(plain, "libmosquitto"));
  EXPECT_FALSE(maps(plain, "libssl"));
  EXPECT_FALSE(maps(plain, "libcrypto"));

  MosquittoBroker broker;
  ASSERT_TRUE(broker.running());
  RecorderProcess fleet(device->port(), {"--duration", "30", "--mqtt", broker.url()});
  ASSERT_TRUE(fleet.waitForText("connected to the MQTT broker", 10s)) << fleet.log();
  EXPECT_TRUE(maps(fleet, "libmosquitto"));
}

TEST(RecorderFootprint, LoadsTheWebAndRtspServersOnlyForHttpOrRtsp) {
  auto device = startSequenceDevice();
  ASSERT_TRUE(device);
  RecorderProcess plain(device->port(), {"--duration", "30"});
  ASSERT_TRUE(plain.waitForText(": live", 10s)) << plain.log();
  for (const char* library :
       {"wirc-recorder-servers", "libsoup", "libkrb5", "libgstrtspserver", "libgstwebrtc"})
    EXPECT_FALSE(maps(plain, library)) << library;

  RecorderProcess web(device->port(), {"--duration", "30", "--http", "127.0.0.1:0"});
  ASSERT_TRUE(web.waitForText("live view at http://", 10s)) << web.log();
  EXPECT_TRUE(maps(web, "wirc-recorder-servers.so"));
  EXPECT_TRUE(maps(web, "libsoup-3.0"));
  RecorderProcess rtsp(device->port(), {"--duration", "30", "--rtsp", "127.0.0.1:0"});
  ASSERT_TRUE(rtsp.waitForText("RTSP at rtsp://", 10s)) << rtsp.log();
  EXPECT_TRUE(maps(rtsp, "libgstrtspserver"));
}

TEST(RecorderFootprint, WithoutItsServersModuleTheWebServerIsRefusedWithTheReason) {
  // The executable alone, away from the lib/ beside its bin/.
  fs::path folder = fs::path(::testing::TempDir()) / ("alone-" + std::to_string(getpid()));
  fs::create_directories(folder);
  fs::copy_file(WIRC_RECORDER, folder / "wirc-recorder", fs::copy_options::overwrite_existing);
  fs::path plugins = fs::path(WIRC_RECORDER).parent_path().parent_path() / "gst-plugins";
  auto run =
      runCommand("GST_PLUGIN_PATH='" + plugins.string() + "' " +
                 (folder / "wirc-recorder").string() + " --device 127.0.0.1:9 --out '" +
                 (folder / "recordings").string() + "' --http 127.0.0.1:0 --duration 10 2>&1");
  EXPECT_EQ(run.exitCode, 1) << run.output;
  // Where it looked: lib/ beside the folder of the executable.
  EXPECT_NE(run.output.find("the web, RTSP and Foxglove servers cannot be loaded: " +
                            (folder.parent_path() / "lib").string()),
            std::string::npos)
      << run.output;
  fs::remove_all(folder);
}

TEST(RecorderFootprint, RunsWithGlibSlicesOnMalloc) {
  if (glib_check_version(2, 76, 0) == nullptr) GTEST_SKIP() << "GLib 2.76 and later use malloc";
  auto device = startSequenceDevice();
  ASSERT_TRUE(device);
  RecorderProcess recorder(device->port(), {"--duration", "30"});
  ASSERT_TRUE(recorder.waitForText(": live", 10s)) << recorder.log();
  std::string environment = procFile(recorder.pid(), "environ");
  EXPECT_NE(environment.find(std::string("G_SLICE=always-malloc\0", 22)), std::string::npos);
  // Started again under its own name (top, pgrep and killall go by it).
  EXPECT_EQ(procFile(recorder.pid(), "comm"), "wirc-recorder\n");
}

}  // namespace
