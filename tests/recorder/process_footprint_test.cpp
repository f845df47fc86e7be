// What a running wirc-recorder holds beside its cameras: libraries it was
// not asked to use are not loaded (libmosquitto brings OpenSSL, 1.8 MB
// resident), and GLib's per-thread slice caches are off.
#include <glib.h>
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "mqtt_broker.h"
#include "recorder_process.h"
#include "simulated_device.h"

namespace {

using namespace wircam::testing;
using namespace std::chrono_literals;

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

TEST(RecorderFootprint, RunsWithGlibSlicesOnMalloc) {
  if (glib_check_version(2, 76, 0) == nullptr) GTEST_SKIP() << "GLib 2.76 and later use malloc";
  auto device = startSequenceDevice();
  ASSERT_TRUE(device);
  RecorderProcess recorder(device->port(), {"--duration", "30"});
  ASSERT_TRUE(recorder.waitForText(": live", 10s)) << recorder.log();
  std::string environment = procFile(recorder.pid(), "environ");
  EXPECT_NE(environment.find(std::string("G_SLICE=always-malloc\0", 22)), std::string::npos);
}

}  // namespace
