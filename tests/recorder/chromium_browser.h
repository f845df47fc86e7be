// One headless Chromium for a whole test program, started at its first page
// and ended with the program: each page gets a browser context of its own
// (DevToolsPage), as fresh as a new profile, without paying for a browser's
// start (about a second of the processor) in every test.
#pragma once

#include <sys/types.h>

#include <filesystem>
#include <string>
#include <vector>

namespace wircam::testing {

class ChromiumBrowser {
 public:
  // The program's browser started with `extraFlags` (one browser for each
  // set of flags asked for), its profile under `folder`; nullptr, with the
  // reason on stderr, if it cannot start.
  static ChromiumBrowser* shared(const std::filesystem::path& folder,
                                 const std::vector<std::string>& extraFlags);
  ~ChromiumBrowser();
  ChromiumBrowser(const ChromiumBrowser&) = delete;
  ChromiumBrowser& operator=(const ChromiumBrowser&) = delete;

  // ws://127.0.0.1:PORT/devtools/browser/ID: the browser's own target.
  const std::string& webSocketUrl() const { return webSocketUrl_; }
  // ws://127.0.0.1:PORT/devtools/page/ID: a page's.
  std::string pageWebSocketUrl(const std::string& targetId) const;

 private:
  ChromiumBrowser() = default;
  bool start(const std::vector<std::string>& extraFlags);

  std::filesystem::path profile_;
  pid_t pid_ = -1;
  std::string origin_;  // ws://127.0.0.1:PORT
  std::string webSocketUrl_;
};

}  // namespace wircam::testing
