#include "prometheus_server.h"

#include <glib.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "common/socket.h"
#include "http_fetch.h"
#include "wait_for.h"

namespace wircam::testing {

namespace fs = std::filesystem;

bool prometheusInstalled() {
  gchar* path = g_find_program_in_path("prometheus");
  bool found = path != nullptr;
  g_free(path);
  return found;
}

PrometheusServer::PrometheusServer(const std::string& target, const std::string& token) {
  static int count = 0;
  folder_ = fs::temp_directory_path() /
            ("wirc-prometheus-" + std::to_string(getpid()) + "-" + std::to_string(++count));
  fs::remove_all(folder_);
  fs::create_directories(folder_ / "data");
  std::ofstream(folder_ / "token") << token;
  std::ofstream(folder_ / "prometheus.yml")
      << "global:\n  scrape_interval: 1s\n  evaluation_interval: 1s\n"
      << "scrape_configs:\n  - job_name: wircam\n    authorization:\n"
      << "      type: Bearer\n      credentials_file: " << (folder_ / "token").string() << "\n"
      << "    static_configs:\n      - targets: ['" << target << "']\n";
  // A port free now; should another test take it first, prometheus exits
  // and ready() says so.
  uint16_t port = 0;
  if (auto socket = listenTcp(SocketAddress::loopback(0)))
    port = localAddress(socket->get()).port();
  url_ = "http://127.0.0.1:" + std::to_string(port) + "/";
  std::string config = "--config.file=" + (folder_ / "prometheus.yml").string();
  std::string data = "--storage.tsdb.path=" + (folder_ / "data").string();
  std::string listen = "--web.listen-address=127.0.0.1:" + std::to_string(port);
  fs::path log = folder_ / "prometheus.log";
  pid_ = fork();
  if (pid_ == 0) {
    if (!freopen(log.c_str(), "w", stdout) || !freopen(log.c_str(), "w", stderr)) _exit(126);
    execlp("prometheus", "prometheus", config.c_str(), data.c_str(), listen.c_str(), nullptr);
    _exit(127);
  }
  ready_ = waitFor(
      [&] { return waitpid(pid_, nullptr, WNOHANG) == 0 && fetch(url_ + "-/ready").status == 200; },
      std::chrono::milliseconds(20000));
}

PrometheusServer::~PrometheusServer() {
  if (pid_ > 0) {
    kill(pid_, SIGKILL);
    waitpid(pid_, nullptr, 0);
  }
  fs::remove_all(folder_);
}

std::optional<double> PrometheusServer::query(const std::string& expression) const {
  gchar* escaped = g_uri_escape_string(expression.c_str(), nullptr, FALSE);
  auto answer = fetch(url_ + "api/v1/query?query=" + escaped);
  g_free(escaped);
  auto json = nlohmann::json::parse(answer.body, nullptr, false);
  if (!json.is_object() || json.value("status", "") != "success") return std::nullopt;
  const auto& result = json["data"]["result"];
  if (!result.is_array() || result.empty()) return std::nullopt;
  // [timestamp, "value"]
  return std::stod(result[0]["value"][1].get<std::string>());
}

std::string PrometheusServer::log() const {
  std::ifstream in(folder_ / "prometheus.log");
  return std::string((std::istreambuf_iterator<char>(in)), {});
}

}  // namespace wircam::testing
