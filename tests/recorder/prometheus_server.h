// Debian's prometheus on a loopback port of its own, scraping one target
// every second with a bearer token read from a file, and its query API: the
// metrics test's real scraper.
#pragma once

#include <sys/types.h>

#include <filesystem>
#include <optional>
#include <string>

namespace wircam::testing {

bool prometheusInstalled();

class PrometheusServer {
 public:
  // Scrapes http://`target`/metrics (HOST:PORT) with `token` as the bearer.
  PrometheusServer(const std::string& target, const std::string& token);
  ~PrometheusServer();
  PrometheusServer(const PrometheusServer&) = delete;
  PrometheusServer& operator=(const PrometheusServer&) = delete;

  bool ready() const { return ready_; }
  // An instant query's first value, or nothing (no such series yet).
  std::optional<double> query(const std::string& expression) const;
  std::string log() const;

 private:
  std::filesystem::path folder_;
  std::string url_;
  pid_t pid_ = -1;
  bool ready_ = false;
};

}  // namespace wircam::testing
