// No socket of the recorder shares its port by accident: every UDP port it
// holds is its own (128 cameras, 128 stream ports and more, none twice), and
// no other socket can bind one, with or without SO_REUSEADDR, so no other
// program can take a camera's stream.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "misbehaving_peers.h"
#include "recorder_process.h"
#include "wait_for.h"

namespace {

namespace fs = std::filesystem;
using namespace wircam::testing;
using namespace std::chrono_literals;

// The local ports of the UDP sockets process `pid` holds, one entry per
// socket (a port held twice appears twice). Read by socket: /proc/net/udp
// is read a page at a time, and a line can come twice when sockets open or
// close between two reads (seen once under load).
std::vector<uint16_t> udpPortsOf(pid_t pid) {
  std::set<std::string> inodes;
  for (const auto& fd : fs::directory_iterator("/proc/" + std::to_string(pid) + "/fd")) {
    std::error_code error;
    auto target = fs::read_symlink(fd.path(), error).string();
    if (!error && target.rfind("socket:[", 0) == 0)
      inodes.insert(target.substr(8, target.size() - 9));
  }
  std::map<std::string, uint16_t> portOf;  // by socket inode
  std::ifstream table("/proc/net/udp");
  std::string line;
  std::getline(table, line);  // the header
  while (std::getline(table, line)) {
    std::istringstream fields(line);
    std::string slot, local, remote, state, queues, timer, retransmits, uid, timeout, inode;
    fields >> slot >> local >> remote >> state >> queues >> timer >> retransmits >> uid >>
        timeout >> inode;
    if (inodes.count(inode))
      portOf[inode] =
          static_cast<uint16_t>(std::stoul(local.substr(local.find(':') + 1), nullptr, 16));
  }
  std::vector<uint16_t> ports;
  for (const auto& [inode, port] : portOf) ports.push_back(port);
  return ports;
}

// Whether a fresh UDP socket can bind 127.0.0.1:port.
bool canBind(uint16_t port, bool reuseAddress) {
  int fd = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  int on = 1;
  if (reuseAddress) setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &on, sizeof on);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(port);
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  bool bound = bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) == 0;
  close(fd);
  return bound;
}

TEST(RecorderUdpPorts, ManyCamerasHoldDistinctPortsThatNoOtherSocketCanBind) {
  constexpr int kDevices = 128;
  std::vector<std::unique_ptr<ScriptedPeer>> devices;
  std::vector<std::string> arguments = {"--stall-timeout", "3600"};
  for (int i = 0; i < kDevices; ++i) {
    devices.push_back(std::make_unique<ScriptedPeer>());
    devices.back()->play({.chunks = {devices.back()->wst()}, .statusReports = 1});
    if (i == 0) continue;  // the recorder's own --device
    arguments.push_back("--device");
    arguments.push_back("127.0.0.1:" + std::to_string(devices.back()->port()));
  }
  RecorderProcess recorder(devices[0]->port(), arguments);
  // Every camera has started (its stream socket is bound) once its device
  // saw a login.
  ASSERT_TRUE(waitFor(
      [&] {
        for (const auto& device : devices)
          if (device->connections() == 0) return false;
        return true;
      },
      patience(30000ms)))
      << recorder.log();
  auto ports = udpPortsOf(recorder.pid());
  std::map<uint16_t, int> holders;
  for (uint16_t port : ports) ++holders[port];
  EXPECT_GE(ports.size(), static_cast<size_t>(kDevices)) << "a stream socket per camera";
  for (const auto& [port, count] : holders) EXPECT_EQ(count, 1) << "port " << port << " shared";
  for (const auto& [port, count] : holders) {
    EXPECT_FALSE(canBind(port, false)) << port;
    EXPECT_FALSE(canBind(port, true)) << port << " with SO_REUSEADDR";
  }
  // It stops (how fast 128 cameras stop is bench_recorder_streams' to
  // measure: 3.0 s was once just too short beside a build).
  recorder.signal(SIGINT);
  EXPECT_TRUE(recorder.waitExit(patience(15000ms)).has_value()) << recorder.log();
}

}  // namespace
