// What wirc-recorder --http answers to requests it does not serve as asked,
// read off the socket as a stranger's client would: each refusal with its
// reason (JSON under /api/) and the headers RFC 9110 asks of it, and a live
// stream that answers before its camera has a frame.
#include <gtest/gtest.h>
#include <poll.h>

#include <chrono>
#include <fstream>
#include <nlohmann/json.hpp>
#include <thread>

#include "raw_http.h"
#include "recorder_process.h"
#include "simulated_device.h"
#include "wait_for.h"

namespace {

using namespace wircam::testing;
using std::chrono::milliseconds;

// A vehicle that logs in and streams, but whose every datagram is lost: its
// camera never has a frame. Nothing is recorded, so the test's own files
// are the only recordings.
struct SilentCameraRecorder {
  std::unique_ptr<wircam::wirc::Device> device = startSequenceDevice(0, 15, {.loss = 1.0});
  std::unique_ptr<RecorderProcess> recorder;
  uint16_t port = 0;
  SilentCameraRecorder() {
    recorder = std::make_unique<RecorderProcess>(
        device->port(), std::vector<std::string>{"--http", "127.0.0.1:0", "--duration", "60"});
    if (auto url = recorder->waitForLog("http://", milliseconds(10000))) port = portOf(*url);
  }
  std::string camera() const { return "127.0.0.1-" + std::to_string(device->port()) + "-cam0"; }
  std::string ask(const std::string& method, const std::string& path) const {
    return answerTo(port,
                    method + " " + path + " HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n");
  }
};

std::string errorOf(const std::string& answer) {
  auto body = nlohmann::json::parse(bodyOf(answer), nullptr, false);
  return body.is_object() ? body.value("error", "") : "";
}

TEST(WircRecorderHttpStatuses, AMethodAPathDoesNotServeIs405WithWhatItDoesServe) {
  SilentCameraRecorder served;
  ASSERT_NE(served.port, 0) << served.recorder->log();
  struct Case {
    std::string method, path, allow;
  };
  for (const Case& c :
       {Case{"GET", "/api/cameras/" + served.camera() + "/follow", "POST"},
        Case{"DELETE", "/api/cameras", "GET"}, Case{"POST", "/api/status", "GET, HEAD"},
        Case{"GET", "/api/recordings/a.mkv", "DELETE"},
        Case{"POST", "/recordings/a.mkv", "GET, HEAD, DELETE"}, Case{"HEAD", "/api/cameras", "GET"},
        Case{"GET", "/api/config/reload", "POST"},
        Case{"GET", "/api/cameras/" + served.camera() + "/whep/s1", "DELETE"}}) {
    auto answer = served.ask(c.method, c.path);
    SCOPED_TRACE(c.method + " " + c.path + ":\n" + answer);
    EXPECT_EQ(answer.rfind("HTTP/1.1 405 ", 0), 0u);
    EXPECT_EQ(headerOf(answer, "Allow"), c.allow);
    EXPECT_EQ(headerOf(answer, "Content-Type"), "application/json");
    if (c.method != "HEAD") {  // (a HEAD's answer has no body)
      EXPECT_NE(errorOf(answer).find(c.method + " is not served here"), std::string::npos);
    }
  }
  // HEAD where it is served: the GET's headers, no body.
  auto head = served.ask("HEAD", "/api/status");
  EXPECT_EQ(head.rfind("HTTP/1.1 200 ", 0), 0u) << head;
  EXPECT_EQ(headerOf(head, "Content-Type"), "application/json") << head;
  EXPECT_EQ(bodyOf(head), "") << head;
  // A path that names nothing is 404, whatever the method.
  EXPECT_EQ(served.ask("DELETE", "/api/nothing").rfind("HTTP/1.1 404 ", 0), 0u);
}

TEST(WircRecorderHttpStatuses, AnEncodedDotDotIs400WithItsReasonAndARangePastTheEndIs416) {
  SilentCameraRecorder served;
  ASSERT_NE(served.port, 0) << served.recorder->log();
  // libsoup refuses these before our handlers; the reason goes with it.
  for (const char* method : {"GET", "DELETE"}) {
    auto api = served.ask(method, "/api/recordings/..%2Fx");
    EXPECT_EQ(api.rfind("HTTP/1.1 400 ", 0), 0u) << api;
    EXPECT_EQ(headerOf(api, "Content-Type"), "application/json") << api;
    EXPECT_NE(errorOf(api).find("'..'"), std::string::npos) << api;
  }
  auto file = served.ask("GET", "/recordings/..%2F..%2Fetc%2Fpasswd");
  EXPECT_EQ(file.rfind("HTTP/1.1 400 ", 0), 0u) << file;
  EXPECT_NE(bodyOf(file).find("'..'"), std::string::npos) << file;

  std::ofstream(served.recorder->out() / "notes.jsonl") << std::string(100, 'n');
  auto range = [&](const std::string& bytes) {
    return answerTo(served.port,
                    "GET /recordings/notes.jsonl HTTP/1.1\r\nHost: x\r\nRange: bytes=" + bytes +
                        "\r\nConnection: close\r\n\r\n");
  };
  auto past = range("100-");
  EXPECT_EQ(past.rfind("HTTP/1.1 416 ", 0), 0u) << past;
  EXPECT_EQ(headerOf(past, "Content-Range"), "bytes */100") << past;
  EXPECT_NE(errorOf(past).find("100 bytes"), std::string::npos) << past;
  auto last = range("99-");
  EXPECT_EQ(last.rfind("HTTP/1.1 206 ", 0), 0u) << last;
  EXPECT_EQ(headerOf(last, "Content-Range"), "bytes 99-99/100") << last;
  EXPECT_EQ(bodyOf(last), "n") << last;
}

// libsoup drops a head over 64 KiB without a word (a reset); RFC 9110 has
// 414 and 431, with a reason, and the client reads them before the close.
TEST(WircRecorderHttpStatuses, AnOverlongRequestLineIs414AndOverlongHeadersAre431) {
  SilentCameraRecorder served;
  ASSERT_NE(served.port, 0) << served.recorder->log();
  auto query = answerTo(served.port, "GET /api/recordings?camera=" + std::string(200 * 1024, 'q') +
                                         " HTTP/1.1\r\nHost: x\r\n\r\n");
  EXPECT_EQ(query.rfind("HTTP/1.1 414 ", 0), 0u) << query.substr(0, 200);
  EXPECT_EQ(headerOf(query, "Content-Type"), "application/json") << query;
  EXPECT_NE(errorOf(query).find("request line is over 64 KiB"), std::string::npos) << query;
  auto header = answerTo(served.port, "GET /api/status HTTP/1.1\r\nHost: x\r\nX-Big: " +
                                          std::string(100 * 1024, 'h') + "\r\n\r\n");
  EXPECT_EQ(header.rfind("HTTP/1.1 431 ", 0), 0u) << header.substr(0, 200);
  EXPECT_NE(errorOf(header).find("header fields are over 64 KiB"), std::string::npos) << header;
  // A head near the bound, in pieces, is still served.
  auto fd = wircam::connectTcp(wircam::SocketAddress::loopback(served.port));
  ASSERT_TRUE(fd.has_value());
  std::string near = "GET /api/status HTTP/1.1\r\nHost: x\r\nConnection: close\r\nX-Big: " +
                     std::string(60 * 1024, 'n');
  for (size_t at = 0; at < near.size(); at += 20 * 1024) {
    std::string piece = near.substr(at, 20 * 1024);
    ::send(fd->get(), piece.data(), piece.size(), MSG_NOSIGNAL);
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ::send(fd->get(), "\r\n\r\n", 4, MSG_NOSIGNAL);
  char status[16] = {};
  pollfd readable{fd->get(), POLLIN, 0};
  ASSERT_GT(::poll(&readable, 1, 5000), 0);
  ASSERT_GT(::recv(fd->get(), status, sizeof status - 1, 0), 0);
  EXPECT_EQ(std::string(status).rfind("HTTP/1.1 200 ", 0), 0u) << status;
}

TEST(WircRecorderHttpStatuses, ALiveStreamAnswersAtOnceBeforeItsCamerasFirstFrame) {
  SilentCameraRecorder served;
  ASSERT_NE(served.port, 0) << served.recorder->log();
  ASSERT_TRUE(waitFor(
      [&] { return served.ask("GET", "/api/cameras").find(served.camera()) != std::string::npos; },
      milliseconds(10000)))
      << served.recorder->log();
  // Headers within a second, though no part will follow.
  auto answer =
      answerTo(served.port, "GET /live/" + served.camera() + ".mjpg HTTP/1.1\r\nHost: x\r\n\r\n",
               true, 1000);
  EXPECT_EQ(answer.rfind("HTTP/1.1 200 ", 0), 0u) << answer << served.recorder->log();
  EXPECT_EQ(headerOf(answer, "Content-Type"), "multipart/x-mixed-replace; boundary=wircframe")
      << answer;
  EXPECT_EQ(answer.find("image/jpeg"), std::string::npos) << "a frame from a camera that has none";
}

}  // namespace
