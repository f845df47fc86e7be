// wirc-recorder --http against hostile clients, over raw sockets: a body it
// never reads, connections it does not keep, files it does not follow, and
// an address it does not open to the network unless told, and connections
// that are idle, half-open or many from one address, which never starve it.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <libsoup/soup.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>

#include <algorithm>
#include <nlohmann/json.hpp>
#include <thread>

#include "common/socket.h"
#include "main_loop_until.h"
#include "process_memory.h"
#include "raw_http.h"
#include "recorder_process.h"
#include "signed_in_page.h"
#include "simulated_device.h"
#include "wait_for.h"
#include "websocket_test_client.h"

namespace {

// What a hostile request may add to the recorder's memory. Under a
// sanitizer each allocation costs several times more (shadow memory).
#if defined(__SANITIZE_THREAD__) || defined(__SANITIZE_ADDRESS__)
constexpr long kMemoryLimitKb = 200 * 1024;
#else
constexpr long kMemoryLimitKb = 20 * 1024;
#endif

namespace fs = std::filesystem;
using namespace wircam::testing;
using std::chrono::milliseconds;

struct ServedRecorder {
  std::unique_ptr<wircam::wirc::Device> device = startSequenceDevice();
  std::unique_ptr<RecorderProcess> recorder;
  std::string url;
  explicit ServedRecorder(std::vector<std::string> extra) {
    extra.insert(extra.end(), {"--duration", "60"});
    recorder = std::make_unique<RecorderProcess>(device->port(), extra);
    url = recorder->waitForLog("http://", milliseconds(10000)).value_or("");
  }
};

TEST(WircRecorderHttpLimits, ListensOnThisMachineOnlyUnlessAnAddressIsGiven) {
  ServedRecorder served({"--http", ":0"});
  ASSERT_FALSE(served.url.empty()) << served.recorder->log();
  EXPECT_EQ(served.url.rfind("http://127.0.0.1:", 0), 0u) << served.url;
}

TEST(WircRecorderHttpLimits, ABodyDeclaredAsAGigabyteIsRefusedUnread) {
  ServedRecorder served({"--http", "127.0.0.1:0"});
  ASSERT_FALSE(served.url.empty()) << served.recorder->log();
  long before = residentKb(served.recorder->pid());
  std::string body(1 << 20, 'x');
  std::string put =
      "PUT /api/status HTTP/1.1\r\nHost: x\r\nContent-Length: 1000000000\r\n\r\n" + body;
  EXPECT_NE(statusLine(portOf(served.url), put).find("405"), std::string::npos);
  // POST is served (the page's control), but never with a body.
  std::string post =
      "POST /api/cameras/x/follow HTTP/1.1\r\nHost: x\r\nContent-Length: 1000000000\r\n\r\n" + body;
  EXPECT_NE(statusLine(portOf(served.url), post).find("413"), std::string::npos);
  std::string get = "GET /api/status HTTP/1.1\r\nHost: x\r\nContent-Length: 1000000000\r\n\r\n";
  EXPECT_NE(statusLine(portOf(served.url), get).find("413"), std::string::npos);
  EXPECT_LT(residentKb(served.recorder->pid()) - before, kMemoryLimitKb);
}

TEST(WircRecorderHttpLimits, ARefusedBodyIsAnsweredWithItsReasonInJson) {
  ServedRecorder served({"--http", "127.0.0.1:0"});
  ASSERT_FALSE(served.url.empty()) << served.recorder->log();
  // A WHEP offer over the cap: 413, and why, as every error of the API.
  auto answer = answerTo(portOf(served.url),
                         "POST /api/cameras/x-cam0/whep HTTP/1.1\r\nHost: x\r\n"
                         "Content-Type: application/sdp\r\nContent-Length: 20000\r\n\r\n");
  EXPECT_EQ(answer.rfind("HTTP/1.1 413 ", 0), 0u) << answer;
  EXPECT_NE(answer.find("Content-Type: application/json"), std::string::npos) << answer;
  auto body = nlohmann::json::parse(answer.substr(answer.find("\r\n\r\n") + 4), nullptr, false);
  EXPECT_EQ(body.value("error", ""), "the offer is 20000 bytes; at most 16384") << answer;
  auto put = answerTo(portOf(served.url),
                      "PUT /api/status HTTP/1.1\r\nHost: x\r\nContent-Length: 5\r\n\r\n");
  EXPECT_EQ(put.rfind("HTTP/1.1 405 ", 0), 0u) << put;
  EXPECT_NE(put.find("{\"error\":\"method PUT is not served"), std::string::npos) << put;
}

TEST(WircRecorderHttpLimits, AnEndlessHeaderIsCutOffWithoutHoldingMemory) {
  ServedRecorder served({"--http", "127.0.0.1:0"});
  ASSERT_FALSE(served.url.empty()) << served.recorder->log();
  long before = residentKb(served.recorder->pid());
  auto fd = wircam::connectTcp(wircam::SocketAddress::loopback(portOf(served.url)));
  ASSERT_TRUE(fd.has_value());
  std::string start = "GET / HTTP/1.1\r\nHost: x\r\nX-Big: ";
  ::send(fd->get(), start.data(), start.size(), MSG_NOSIGNAL);
  std::string filler(64 * 1024, 'a');
  size_t sent = 0;
  while (sent < (64u << 20) && ::send(fd->get(), filler.data(), filler.size(), MSG_NOSIGNAL) > 0)
    sent += filler.size();
  EXPECT_LT(sent, 64u << 20) << "64 MB of header and still reading";
  EXPECT_LT(residentKb(served.recorder->pid()) - before, kMemoryLimitKb);
}

// A connection to the server from 127.0.0.`host` (all of 127/8 is this
// machine), which may send `start`; invalid when refused.
wircam::UniqueFd connectFrom(int host, uint16_t port, const std::string& start = "") {
  wircam::UniqueFd fd(::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0));
  sockaddr_in from{.sin_family = AF_INET, .sin_port = 0, .sin_addr = {htonl(0x7F000000u | host)}};
  sockaddr_in to{.sin_family = AF_INET, .sin_port = htons(port), .sin_addr = {htonl(0x7F000001u)}};
  if (::bind(fd.get(), reinterpret_cast<sockaddr*>(&from), sizeof from) != 0 ||
      ::connect(fd.get(), reinterpret_cast<sockaddr*>(&to), sizeof to) != 0)
    return {};
  if (!start.empty()) ::send(fd.get(), start.data(), start.size(), MSG_NOSIGNAL);
  return fd;
}

bool closedByServer(const wircam::UniqueFd& fd) {
  char byte;
  pollfd p{fd.get(), POLLIN, 0};
  return ::poll(&p, 1, 0) > 0 && ::recv(fd.get(), &byte, 1, MSG_DONTWAIT) <= 0;
}

bool allClosedByServer(const std::vector<wircam::UniqueFd>& connections) {
  return std::all_of(connections.begin(), connections.end(), closedByServer);
}

TEST(WircRecorderHttpLimits, IdleConnectionsNeverStarveTheServer) {
  ServedRecorder served({"--http", "127.0.0.1:0", "--http-idle-timeout", "2"});
  ASSERT_FALSE(served.url.empty()) << served.recorder->log();
  uint16_t port = portOf(served.url);
  for (int round = 0; round < 2; ++round) {
    // More than one address may hold: past it they are closed at once, the
    // rest once they have been silent for the idle timeout.
    std::vector<wircam::UniqueFd> silent;
    for (int i = 0; i < 75; ++i) silent.push_back(connectFrom(1, port));
    ASSERT_TRUE(waitFor([&] { return allClosedByServer(silent); }, milliseconds(2000 + 2000)))
        << "round " << round;
    silent.clear();
    // Every place given back: a request gets through at once.
    EXPECT_NE(statusLine(port, "GET /api/status HTTP/1.1\r\nHost: x\r\n\r\n").find("200"),
              std::string::npos)
        << "round " << round;
  }
}

TEST(WircRecorderHttpLimits, HalfOpenRequestsAreClosedWithinTheIdleTimeoutAndASecond) {
  ServedRecorder served({"--http", "127.0.0.1:0", "--http-idle-timeout", "2"});
  ASSERT_FALSE(served.url.empty()) << served.recorder->log();
  uint16_t port = portOf(served.url);
  // 200 from four addresses: the server's whole cap, and more.
  std::vector<wircam::UniqueFd> connections;
  auto first = std::chrono::steady_clock::now();
  for (int i = 0; i < 200; ++i) connections.push_back(connectFrom(1 + i % 4, port, "GET /api/sta"));
  // (Connecting takes a while: past the listen backlog, SYNs are retried.)
  ASSERT_TRUE(waitFor([&] { return allClosedByServer(connections); }, milliseconds(2000 + 1000)));
  // The first ones admitted were given their whole idle timeout.
  EXPECT_GE(std::chrono::steady_clock::now() - first, milliseconds(1900));
  connections.clear();
  EXPECT_NE(statusLine(port, "GET /api/status HTTP/1.1\r\nHost: x\r\n\r\n").find("200"),
            std::string::npos);
}

TEST(WircRecorderHttpLimits, OneAddressCannotTakeEveryConnection) {
  ServedRecorder served({"--http", "127.0.0.1:0", "--http-idle-timeout", "30"});
  ASSERT_FALSE(served.url.empty()) << served.recorder->log();
  uint16_t port = portOf(served.url);
  std::vector<wircam::UniqueFd> hog;
  for (int i = 0; i < 150; ++i) hog.push_back(connectFrom(7, port));
  // Those past the per-address cap are closed at once; another address is
  // served while the rest stay open.
  EXPECT_TRUE(
      waitFor([&] { return std::count_if(hog.begin(), hog.end(), closedByServer) >= 150 - 64; },
              milliseconds(3000)));
  auto fd = connectFrom(9, port, "GET /api/status HTTP/1.1\r\nHost: x\r\n\r\n");
  char answer[16] = {};
  pollfd p{fd.get(), POLLIN, 0};
  ASSERT_GT(::poll(&p, 1, 5000), 0);
  ASSERT_GT(::recv(fd.get(), answer, sizeof answer - 1, 0), 0);
  EXPECT_EQ(std::string(answer).substr(0, 12), "HTTP/1.1 200");
  EXPECT_EQ(std::count_if(hog.begin(), hog.end(), closedByServer), 150 - 64);
}

TEST(WircRecorderHttpLimits, ASymbolicLinkInTheRecordingsFolderIsNeitherListedNorServed) {
  ServedRecorder served({"--http", "127.0.0.1:0"});
  ASSERT_FALSE(served.url.empty()) << served.recorder->log();
  fs::create_symlink("/etc/passwd", served.recorder->out() / "passwd.jsonl");
  uint16_t port = portOf(served.url);
  EXPECT_NE(
      statusLine(port, "GET /recordings/passwd.jsonl HTTP/1.1\r\nHost: x\r\n\r\n").find("404"),
      std::string::npos);
  auto fd = wircam::connectTcp(wircam::SocketAddress::loopback(port));
  std::string request = "GET /recordings HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n";
  ::send(fd->get(), request.data(), request.size(), MSG_NOSIGNAL);
  std::string listing;
  char chunk[4096];
  ssize_t n;
  while ((n = ::recv(fd->get(), chunk, sizeof chunk, 0)) > 0) listing.append(chunk, n);
  EXPECT_EQ(listing.find("passwd"), std::string::npos) << listing;
}

TEST(WircRecorderHttpLimits, ALongDriveMessageIsRefusedWithNeutralAndAHugeOneClosesItsSocket) {
  FollowedCar car;
  ASSERT_TRUE(car.device);
  RecorderProcess recorder(car.device->port(), {"--detect", "tag36h11", "--follow", "--http",
                                                "127.0.0.1:0", "--http-token", kToken});
  auto url = recorder.waitForLog("http://", milliseconds(10000));
  ASSERT_TRUE(url) << recorder.log();
  ASSERT_TRUE(recorder.waitForText(": live", milliseconds(10000))) << recorder.log();
  // libsoup's own client, which offers permessage-deflate as browsers do.
  WebSocketTestClient client(
      "ws://" + url->substr(7) + "api/cameras/127.0.0.1-" + std::to_string(car.device->port()) +
          "-cam0/drive",
      {.headers = {{"Authorization", std::string("Bearer ") + kToken}}, .offerDeflate = true});
  ASSERT_TRUE(runMainLoopUntil([&] { return client.connection || client.failed; }));
  ASSERT_TRUE(client.open()) << recorder.log();
  // Over 256 bytes: no command, the vehicle to neutral, the socket open.
  std::string padded = R"({"steering": 0, "throttle": 0, "pad": ")" + std::string(300, ' ') + "\"}";
  soup_websocket_connection_send_text(client.connection, padded.c_str());
  ASSERT_TRUE(runMainLoopUntil([&] { return !client.texts.empty(); }));
  EXPECT_EQ(client.texts[0], R"({"error":"longer than 256 bytes","neutral":true})");
  EXPECT_TRUE(client.open());
  // Over 4 KB closes the socket, however well it compresses: a megabyte of
  // spaces deflated fits in a few hundred bytes, and was read whole. (Its
  // close code may not reach the client: the server closes with most of
  // the megabyte unread, and TCP resets the connection.)
  std::string huge = R"({"pad": ")" + std::string(1 << 20, ' ') + "\"}";
  soup_websocket_connection_send_text(client.connection, huge.c_str());
  EXPECT_TRUE(runMainLoopUntil([&] { return !client.open(); }))
      << client.texts.size() << " answers, the last " << client.texts.back();
}

}  // namespace
