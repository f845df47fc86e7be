// HttpFetcher against a server that breaks its connections mid-body: the
// file comes whole all the same, each connection taken up where the last
// one broke (or from the start, when the server ignores the range).
#include "export/http_fetcher.h"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <fstream>
#include <mutex>
#include <random>
#include <sstream>
#include <thread>
#include <vector>

namespace {

namespace fs = std::filesystem;
using wircam::recorder::HttpFetcher;

// Serves `body` at any path but /missing (a 404), a connection at a time;
// the first `breaks` connections send only `breakAfter` bytes of what they
// owe and close. Ranges ("bytes=N-") are honoured unless `ignoreRanges`.
class BreakingServer {
 public:
  BreakingServer(std::string body, int breaks, size_t breakAfter, bool ignoreRanges = false)
      : body_(std::move(body)),
        breaks_(breaks),
        breakAfter_(breakAfter),
        ignoreRanges_(ignoreRanges) {
    listener_ = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t length = sizeof address;
    if (bind(listener_, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0 ||
        listen(listener_, 8) != 0 ||
        getsockname(listener_, reinterpret_cast<sockaddr*>(&address), &length) != 0)
      return;
    port_ = ntohs(address.sin_port);
    thread_ = std::thread([this] { serve(); });
  }
  ~BreakingServer() {
    shutdown(listener_, SHUT_RDWR);
    close(listener_);
    if (thread_.joinable()) thread_.join();
  }
  std::string url(const std::string& path = "/file") const {
    return "http://127.0.0.1:" + std::to_string(port_) + path;
  }
  std::vector<std::string> requests() const {
    std::lock_guard lock(mutex_);
    return requests_;
  }

 private:
  void serve() {
    for (int connection = 0;; ++connection) {
      int client = accept(listener_, nullptr, nullptr);
      if (client < 0) return;
      std::string head;
      char c;
      while (!head.ends_with("\r\n\r\n") && recv(client, &c, 1, 0) == 1) head += c;
      {
        std::lock_guard lock(mutex_);
        requests_.push_back(head);
      }
      std::string answer;
      if (head.starts_with("GET /missing")) {
        answer = "HTTP/1.1 404 Not Found\r\nContent-Length: 0\r\nConnection: close\r\n\r\n";
      } else {
        size_t from = 0;
        auto range = head.find("Range: bytes=");
        if (range != std::string::npos && !ignoreRanges_)
          from = std::stoul(head.substr(range + 13));
        std::string payload = body_.substr(from);
        answer = (from ? "HTTP/1.1 206 Partial Content\r\nContent-Range: bytes " +
                             std::to_string(from) + "-" + std::to_string(body_.size() - 1) + "/" +
                             std::to_string(body_.size()) + "\r\n"
                       : std::string("HTTP/1.1 200 OK\r\n")) +
                 "Content-Length: " + std::to_string(payload.size()) +
                 "\r\nConnection: close\r\n\r\n";
        answer += connection < breaks_ ? payload.substr(0, breakAfter_) : payload;
      }
      for (size_t sent = 0; sent < answer.size();) {
        ssize_t n = send(client, answer.data() + sent, answer.size() - sent, MSG_NOSIGNAL);
        if (n <= 0) break;
        sent += static_cast<size_t>(n);
      }
      close(client);
    }
  }

  std::string body_;
  int breaks_;
  size_t breakAfter_;
  bool ignoreRanges_;
  int listener_ = -1;
  uint16_t port_ = 0;
  std::thread thread_;
  mutable std::mutex mutex_;
  std::vector<std::string> requests_;
};

std::string randomBytes(size_t size) {
  std::mt19937 generator(7);
  std::string bytes(size, '\0');
  for (auto& b : bytes) b = static_cast<char>(generator());
  return bytes;
}

std::string contentsOf(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

fs::path scratch(const std::string& name) {
  return fs::temp_directory_path() / (name + "-" + std::to_string(getpid()));
}

TEST(HttpFetcher, ABrokenConnectionIsTakenUpWhereItBroke) {
  std::string body = randomBytes(1000000);
  BreakingServer server(body, 2, 300000);
  HttpFetcher fetcher("sesame");
  fs::path file = scratch("fetched");
  EXPECT_EQ(fetcher.download(server.url(), file), std::nullopt);
  EXPECT_TRUE(contentsOf(file) == body) << contentsOf(file).size() << " bytes";
  EXPECT_EQ(fetcher.resumed(), 2);
  auto requests = server.requests();
  ASSERT_EQ(requests.size(), 3u);
  EXPECT_EQ(requests[0].find("Range:"), std::string::npos);
  EXPECT_NE(requests[1].find("Range: bytes=300000-"), std::string::npos) << requests[1];
  EXPECT_NE(requests[2].find("Range: bytes=600000-"), std::string::npos) << requests[2];
  for (const auto& request : requests)
    EXPECT_NE(request.find("Authorization: Bearer sesame"), std::string::npos);
  fs::remove(file);
}

TEST(HttpFetcher, AServerThatIgnoresTheRangeHasTheFileStartedOver) {
  std::string body = randomBytes(500000);
  BreakingServer server(body, 1, 200000, true);
  HttpFetcher fetcher("");
  fs::path file = scratch("fetched-over");
  EXPECT_EQ(fetcher.download(server.url(), file), std::nullopt);
  EXPECT_TRUE(contentsOf(file) == body) << contentsOf(file).size() << " bytes";
  EXPECT_EQ(server.requests().size(), 2u);
  fs::remove(file);
}

TEST(HttpFetcher, A404IsAnErrorUnlessTheFileMayBeMissingAndLeavesNoFile) {
  BreakingServer server("", 0, 0);
  HttpFetcher fetcher("");
  fs::path file = scratch("missing");
  auto problem = fetcher.download(server.url("/missing"), file);
  ASSERT_TRUE(problem);
  EXPECT_NE(problem->find("answered 404"), std::string::npos) << *problem;
  EXPECT_FALSE(fs::exists(file));
  EXPECT_EQ(fetcher.download(server.url("/missing"), file, true), std::nullopt);
  EXPECT_FALSE(fs::exists(file));
  EXPECT_EQ(server.requests().size(), 2u);  // a 404 is not asked again
}

}  // namespace
