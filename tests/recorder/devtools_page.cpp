#include "devtools_page.h"

#include <fstream>
#include <iostream>
#include <thread>
#include <vector>

#include "chromium_browser.h"
#include "wait_for.h"

namespace wircam::testing {

namespace {

using Clock = std::chrono::steady_clock;

// libsoup works on the thread-default context it was created under.
class ContextScope {
 public:
  explicit ContextScope(GMainContext* context) : context_(context) {
    g_main_context_push_thread_default(context_);
  }
  ~ContextScope() { g_main_context_pop_thread_default(context_); }

 private:
  GMainContext* context_;
};

}  // namespace

std::unique_ptr<DevToolsPage> DevToolsPage::launch(const std::filesystem::path& profile, int width,
                                                   int height,
                                                   const std::vector<std::string>& extraFlags) {
  ChromiumBrowser* browser = ChromiumBrowser::shared(profile.parent_path(), extraFlags);
  if (!browser) return nullptr;
  std::unique_ptr<DevToolsPage> page(new DevToolsPage());
  ContextScope scope(page->context_);
  page->session_ = soup_session_new();
  page->browser_ = page->connect(browser->webSocketUrl());
  if (!page->browser_) {
    std::cerr << "cannot attach to chromium at " << browser->webSocketUrl() << "\n";
    return nullptr;
  }
  // A context of its own: no cookie, storage or cache of another test's.
  auto context = page->callOn(page->browser_, "Target.createBrowserContext");
  page->browserContextId_ = context.value("browserContextId", "");
  auto target = page->callOn(page->browser_, "Target.createTarget",
                             {{"url", "about:blank"},
                              {"browserContextId", page->browserContextId_},
                              {"newWindow", true},
                              {"width", width},
                              {"height", height}});
  page->targetId_ = target.value("targetId", "");
  if (page->targetId_.empty()) {
    std::cerr << "chromium made no page: " << context.dump() << " " << target.dump() << "\n";
    return nullptr;
  }
  page->socket_ = page->connect(browser->pageWebSocketUrl(page->targetId_));
  if (page->socket_ && page->keepsFocus() && page->warmUp()) return page;
  std::cerr << "cannot attach to chromium's page " << page->targetId_ << "\n";
  return nullptr;
}

bool DevToolsPage::keepsFocus() {
  // A headless window can lose focus under load, and the page then lets go
  // of every key it holds (its safety for keys released elsewhere): a test
  // driving with a key down found the car at neutral before its hang (a
  // fresh clone), then found that a key pressed again did not drive (CI).
  // Tests press keys into this page alone; it stays focused.
  auto emulated = call("Emulation.setFocusEmulationEnabled", {{"enabled", true}});
  if (!emulated.contains("error")) return true;
  std::cerr << "chromium cannot keep the page focused: " << emulated.dump() << "\n";
  return false;
}

bool DevToolsPage::warmUp() {
  // A fresh profile's first page pays for Chromium's start (its renderer,
  // GPU probing, the font cache): seconds on a loaded 2-core machine, which
  // no test's own bound should have to cover. Paid here, once, with text,
  // an image and a script, on a budget of its own.
  constexpr auto kStartUp = std::chrono::seconds(45);
  auto loaded = call("Page.navigate",
                     {{"url",
                       "data:text/html,<p style='font:16px sans-serif'>wircam</p>"
                       "<canvas id=c></canvas><script>c.getContext('2d')"
                       ".fillText('x',1,10)</script>"}},
                     kStartUp);
  if (loaded.contains("error")) {
    std::cerr << "chromium's first page did not load: " << loaded.dump() << "\n";
    return false;
  }
  if (waitUntil("document.readyState === 'complete'", kStartUp)) return true;
  std::cerr << "chromium's first page did not complete within " << kStartUp.count() << " s\n";
  return false;
}

SoupWebsocketConnection* DevToolsPage::connect(const std::string& webSocketUrl) {
  SoupMessage* message = soup_message_new("GET", webSocketUrl.c_str());
  struct Result {
    SoupWebsocketConnection* socket = nullptr;
    bool done = false;
  } result;
  soup_session_websocket_connect_async(
      session_, message, nullptr, nullptr, G_PRIORITY_DEFAULT, nullptr,
      [](GObject* session, GAsyncResult* async, gpointer data) {
        auto* r = static_cast<Result*>(data);
        r->socket = soup_session_websocket_connect_finish(SOUP_SESSION(session), async, nullptr);
        r->done = true;
      },
      &result);
  auto until = Clock::now() + std::chrono::seconds(10);
  while (!result.done && Clock::now() < until) g_main_context_iteration(context_, TRUE);
  g_object_unref(message);
  if (!result.socket) return nullptr;
  // Screenshots are a few hundred kB.
  soup_websocket_connection_set_max_incoming_payload_size(result.socket, 64 << 20);
  // Both sockets' answers land here; their ids come from one counter.
  g_signal_connect(result.socket, "message",
                   G_CALLBACK(+[](SoupWebsocketConnection*, gint, GBytes* bytes, gpointer data) {
                     auto* self = static_cast<DevToolsPage*>(data);
                     gsize size = 0;
                     const char* text = static_cast<const char*>(g_bytes_get_data(bytes, &size));
                     auto reply =
                         nlohmann::json::parse(std::string_view(text, size), nullptr, false);
                     if (reply.is_object() && reply.contains("id"))
                       self->replies_[std::to_string(reply["id"].get<int>())] = reply;
                   }),
                   this);
  return result.socket;
}

DevToolsPage::~DevToolsPage() {
  {
    ContextScope scope(context_);
    // The context's pages close with it: the browser is left as it was.
    if (!browserContextId_.empty())
      callOn(browser_, "Target.disposeBrowserContext", {{"browserContextId", browserContextId_}},
             std::chrono::seconds(5));
    for (SoupWebsocketConnection* socket : {socket_, browser_})
      if (socket) {
        soup_websocket_connection_close(socket, SOUP_WEBSOCKET_CLOSE_NORMAL, nullptr);
        g_object_unref(socket);
      }
    if (session_) g_object_unref(session_);
    while (g_main_context_iteration(context_, FALSE)) {
    }
  }
  g_main_context_unref(context_);
}

nlohmann::json DevToolsPage::call(const std::string& method, nlohmann::json params,
                                  std::chrono::milliseconds timeout) {
  return callOn(socket_, method, std::move(params), timeout);
}

nlohmann::json DevToolsPage::callOn(SoupWebsocketConnection* socket, const std::string& method,
                                    nlohmann::json params, std::chrono::milliseconds timeout) {
  if (!socket || soup_websocket_connection_get_state(socket) != SOUP_WEBSOCKET_STATE_OPEN)
    return {{"error", "not connected"}};
  ContextScope scope(context_);
  int id = nextId_++;
  soup_websocket_connection_send_text(
      socket, nlohmann::json{{"id", id}, {"method", method}, {"params", params}}.dump().c_str());
  auto key = std::to_string(id);
  for (auto until = Clock::now() + patience(timeout); Clock::now() < until;) {
    if (replies_.contains(key)) {
      auto reply = replies_[key];
      replies_.erase(key);
      if (reply.contains("error")) return {{"error", reply["error"]}};
      return reply.value("result", nlohmann::json::object());
    }
    if (!g_main_context_iteration(context_, FALSE))
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return {{"error", "no answer to " + method}};
}

bool DevToolsPage::navigate(const std::string& url) {
  auto result = call("Page.navigate", {{"url", url}}, std::chrono::seconds(20));
  if (result.contains("error") || result.contains("errorText")) return false;
  // The document parsed and its scripts run: what the tests drive. Not
  // every subresource loaded ('complete'): the live view's MJPEG fallback is
  // an image that never finishes, and a loaded machine may fall back to it
  // before the load event.
  return waitUntil("document.readyState !== 'loading'", std::chrono::seconds(20));
}

nlohmann::json DevToolsPage::evaluate(const std::string& expression) {
  auto result = call("Runtime.evaluate",
                     {{"expression", expression}, {"returnByValue", true}, {"awaitPromise", true}});
  if (result.contains("exceptionDetails") || !result.contains("result")) return nullptr;
  return result["result"].value("value", nlohmann::json());
}

bool DevToolsPage::waitUntil(const std::string& expression, std::chrono::milliseconds timeout) {
  for (auto until = Clock::now() + patience(timeout); Clock::now() < until;) {
    if (evaluate("Boolean(" + expression + ")") == true) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return false;
}

bool DevToolsPage::allowDownloads(const std::filesystem::path& folder) {
  // The browser's to set, for the context (a page's session sets only the
  // default context's).
  auto allowed = callOn(browser_, "Browser.setDownloadBehavior",
                        {{"behavior", "allow"},
                         {"browserContextId", browserContextId_},
                         {"downloadPath", folder.string()}});
  if (allowed.contains("error")) std::cerr << "downloads refused: " << allowed.dump() << "\n";
  return !allowed.contains("error");
}

bool DevToolsPage::setCookie(const std::string& name, const std::string& value,
                             const std::string& url) {
  auto result = call("Network.setCookie", {{"name", name}, {"value", value}, {"url", url}});
  return result.value("success", false);
}

void DevToolsPage::key(const char* type, const std::string& key) {
  // Arrow keys' Windows key codes, which the page's keydown handler reads as event.key.
  static const std::map<std::string, int> codes = {
      {"ArrowLeft", 37}, {"ArrowUp", 38}, {"ArrowRight", 39}, {"ArrowDown", 40}};
  call("Input.dispatchKeyEvent", {{"type", type},
                                  {"key", key},
                                  {"code", key},
                                  {"windowsVirtualKeyCode", codes.count(key) ? codes.at(key) : 0}});
}

void DevToolsPage::click(double x, double y) {
  for (const char* type : {"mousePressed", "mouseReleased"})
    call("Input.dispatchMouseEvent",
         {{"type", type}, {"x", x}, {"y", y}, {"button", "left"}, {"clickCount", 1}});
}

void DevToolsPage::drag(double fromX, double fromY, double toX, double toY) {
  auto mouse = [this](const char* type, double x, double y, int buttons) {
    call("Input.dispatchMouseEvent", {{"type", type},
                                      {"x", x},
                                      {"y", y},
                                      {"button", "left"},
                                      {"buttons", buttons},
                                      {"clickCount", 1}});
  };
  mouse("mousePressed", fromX, fromY, 1);
  // In steps, as a hand moves: each one a pointermove on the way.
  constexpr int kSteps = 8;
  for (int step = 1; step <= kSteps; ++step)
    mouse("mouseMoved", fromX + (toX - fromX) * step / kSteps,
          fromY + (toY - fromY) * step / kSteps, 1);
  mouse("mouseReleased", toX, toY, 0);
}

bool DevToolsPage::screenshot(const std::filesystem::path& png) {
  auto result = call("Page.captureScreenshot", {{"format", "png"}});
  if (!result.contains("data")) return false;
  std::string encoded = result["data"];
  gsize size = 0;
  guchar* bytes = g_base64_decode(encoded.c_str(), &size);
  std::ofstream out(png, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes), static_cast<std::streamsize>(size));
  g_free(bytes);
  return static_cast<bool>(out);
}

void DevToolsPage::pauseScripts() {
  call("Debugger.enable");
  call("Debugger.pause");
}

void DevToolsPage::closeTab() {
  call("Page.close", nlohmann::json::object(), std::chrono::milliseconds(2000));
}

std::pair<double, double> DevToolsPage::centreOf(const std::string& selector) {
  auto box = evaluate("(() => { const r = document.querySelector('" + selector +
                      "').getBoundingClientRect(); return [r.x + r.width / 2, "
                      "r.y + r.height / 2]; })()");
  if (!box.is_array()) return {0, 0};
  return {box[0].get<double>(), box[1].get<double>()};
}

bool DevToolsPage::clickOn(const std::string& selector) {
  // A click lands where the element was a moment before: under load the
  // page can lay out again in between (a first frame, a new row), and the
  // click misses (seen on fresh clones). The page counts the clicks that
  // reach the element; a missed one is made again, up to three times.
  evaluate(
      "if (window.clickWatch) document.removeEventListener('click', window.clickWatch, true); "
      "window.clicksReached = 0; window.clickWatch = e => { if (e.target.closest('" +
      selector +
      "')) ++window.clicksReached; }; "
      "document.addEventListener('click', window.clickWatch, true)");
  for (int attempt = 0; attempt < 3 && evaluate("window.clicksReached") == 0; ++attempt) {
    evaluate("document.querySelector('" + selector + "').scrollIntoView({block: 'center'})");
    auto [x, y] = centreOf(selector);
    click(x, y);
  }
  return evaluate("window.clicksReached") == 1;
}

}  // namespace wircam::testing
