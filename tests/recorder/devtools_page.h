// Debian's chromium, headless, driven through the DevTools protocol over
// its WebSocket (libsoup as the client): load a page, run script in it and
// read the answer, press keys, click, take screenshots, pause its scripts
// (a page that hangs) or close it (a page that goes away). For the tests
// that check the live view as a user would use it.
#pragma once

#include <glib.h>
#include <libsoup/soup.h>
#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

namespace wircam::testing {

class DevToolsPage {
 public:
  // A page of `width`×`height` in a browser context of its own (fresh
  // cookies, storage and cache) of the program's Chromium (ChromiumBrowser:
  // one for each set of `extraFlags`, its profile beside `profile`), that
  // has loaded a first page on a start-up budget of its own (45 s), apart
  // from what the test then bounds; nullptr (with the reason on stderr) if
  // it cannot. Its context is closed with it.
  static std::unique_ptr<DevToolsPage> launch(const std::filesystem::path& profile, int width,
                                              int height,
                                              const std::vector<std::string>& extraFlags = {});
  ~DevToolsPage();
  DevToolsPage(const DevToolsPage&) = delete;
  DevToolsPage& operator=(const DevToolsPage&) = delete;

  // A DevTools command and its result (an {"error": ...} object on failure
  // or after `timeout`; timeouts here stretch under a sanitizer, see
  // patience() in wait_for.h).
  nlohmann::json call(const std::string& method, nlohmann::json params = nlohmann::json::object(),
                      std::chrono::milliseconds timeout = std::chrono::seconds(10));
  // Loads `url` and waits until its document is parsed and its scripts run.
  bool navigate(const std::string& url);
  // The value of a JavaScript expression (promises awaited), or null.
  nlohmann::json evaluate(const std::string& expression);
  // Polls `expression` until it is true.
  bool waitUntil(const std::string& expression,
                 std::chrono::milliseconds timeout = std::chrono::seconds(10));
  // Downloads from this page's context go to `folder`.
  bool allowDownloads(const std::filesystem::path& folder);
  bool setCookie(const std::string& name, const std::string& value, const std::string& url);
  void key(const char* type, const std::string& key);  // type: keyDown or keyUp
  void click(double x, double y);
  // The centre of the first element `selector` names, in page pixels.
  std::pair<double, double> centreOf(const std::string& selector);
  // Clicks it as a user would; whether the click reached it (made again
  // if the page moved it meanwhile).
  bool clickOn(const std::string& selector);
  // The left button pressed at one point, moved and released at another.
  void drag(double fromX, double fromY, double toX, double toY);
  bool screenshot(const std::filesystem::path& png);
  // Stops the page's scripts where they are; the socket stays open.
  void pauseScripts();
  // Closes the tab, as a user closing it would.
  void closeTab();

 private:
  DevToolsPage() = default;
  SoupWebsocketConnection* connect(const std::string& webSocketUrl);
  nlohmann::json callOn(SoupWebsocketConnection* socket, const std::string& method,
                        nlohmann::json params = nlohmann::json::object(),
                        std::chrono::milliseconds timeout = std::chrono::seconds(10));
  // Keeps the page focused whatever its window does (key events).
  bool keepsFocus();
  // Loads a first page with its own start-up budget (DevToolsPage::launch).
  bool warmUp();

  GMainContext* context_ = g_main_context_new();
  SoupSession* session_ = nullptr;
  SoupWebsocketConnection* browser_ = nullptr;  // the browser's own target
  SoupWebsocketConnection* socket_ = nullptr;   // the page's
  std::string browserContextId_;
  std::string targetId_;
  int nextId_ = 1;
  nlohmann::json replies_ = nlohmann::json::object();  // id → message
};

}  // namespace wircam::testing
