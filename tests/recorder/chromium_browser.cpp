#include "chromium_browser.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <thread>

#include "headless_chromium.h"

namespace wircam::testing {

ChromiumBrowser* ChromiumBrowser::shared(const std::filesystem::path& folder,
                                         const std::vector<std::string>& extraFlags) {
  // Ended (killed, its profile removed) when the program exits.
  static std::map<std::vector<std::string>, std::unique_ptr<ChromiumBrowser>> browsers;
  auto& browser = browsers[extraFlags];
  if (browser) {
    if (waitpid(browser->pid_, nullptr, WNOHANG) == 0) return browser.get();
    browser->pid_ = -1;  // gone and reaped: its number may be another's now
  }
  browser.reset(new ChromiumBrowser());
  browser->profile_ =
      processProfile(folder / ("chromium-profile-" + std::to_string(browsers.size())));
  if (browser->start(extraFlags)) return browser.get();
  browser.reset();
  return nullptr;
}

bool ChromiumBrowser::start(const std::vector<std::string>& extraFlags) {
  std::error_code ignored;
  std::filesystem::remove_all(profile_, ignored);
  std::filesystem::create_directories(profile_);
  std::vector<std::string> args = {"chromium"};
  // The window's size is each page's own (Target.createTarget).
  for (auto& flag : chromiumFlags(profile_, 800, 600)) args.push_back(flag);
  args.insert(args.end(), extraFlags.begin(), extraFlags.end());
  // A hidden or idle tab must keep its timers at speed.
  args.insert(args.end(),
              {"--disable-background-timer-throttling", "--disable-renderer-backgrounding",
               "--remote-debugging-address=127.0.0.1", "--remote-debugging-port=0", "about:blank"});
  pid_t parent = getpid();
  pid_ = fork();
  if (pid_ == 0) {
    // Gone with the test program, even one that crashed.
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != parent) _exit(127);
    // Its singleton socket's folder goes with the profile, not into /tmp
    // (a killed browser leaves it behind: thousands over a day of runs).
    setenv("TMPDIR", profile_.c_str(), 1);
    std::vector<char*> argv;
    for (auto& arg : args) argv.push_back(arg.data());
    argv.push_back(nullptr);
    int null = open("/dev/null", O_WRONLY);
    dup2(null, STDOUT_FILENO);
    dup2(null, STDERR_FILENO);
    execvp("chromium", argv.data());
    _exit(127);
  }
  // Chromium writes its port and its own target's path here once listening.
  auto portFile = profile_ / "DevToolsActivePort";
  auto until = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (std::chrono::steady_clock::now() < until) {
    std::ifstream in(portFile);
    std::string port, path;
    if (in && std::getline(in, port) && std::getline(in, path) && !path.empty()) {
      origin_ = "ws://127.0.0.1:" + port;
      webSocketUrl_ = origin_ + path;
      return true;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  std::cerr << "chromium wrote no DevToolsActivePort\n";
  return false;
}

std::string ChromiumBrowser::pageWebSocketUrl(const std::string& targetId) const {
  return origin_ + "/devtools/page/" + targetId;
}

ChromiumBrowser::~ChromiumBrowser() {
  if (pid_ > 0) {
    kill(pid_, SIGKILL);
    waitpid(pid_, nullptr, 0);
  }
  std::error_code ignored;
  std::filesystem::remove_all(profile_, ignored);
}

}  // namespace wircam::testing
