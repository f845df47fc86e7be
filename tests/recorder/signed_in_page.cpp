#include "signed_in_page.h"

#include <gtest/gtest.h>

#include <thread>

namespace wircam::testing {

namespace {

std::vector<std::string> withArgs(std::vector<std::string> extra, bool withToken) {
  extra.insert(extra.end(), {"--http", "127.0.0.1:0", "--duration", "120"});
  if (withToken) extra.insert(extra.end(), {"--http-token", kToken});
  return extra;
}

}  // namespace

FollowedCar::FollowedCar() {
  auto created = sim::FollowScene::create({});
  EXPECT_TRUE(created.has_value());
  scene = std::shared_ptr<sim::FollowScene>(std::move(*created));
  auto started = wirc::Device::start({.port = 0, .fragmentSize = 8000}, scene);
  EXPECT_TRUE(started.has_value());
  device = std::move(*started);
}

bool atNeutral(const wirc::Device& device) {
  auto pulses = device.outputs().pulses;
  return pulses[kSteering] == 1500 && pulses[kThrottle] == 1500;
}

std::chrono::milliseconds untilNeutral(const wirc::Device& device) {
  using Clock = std::chrono::steady_clock;
  auto start = Clock::now();
  while (!atNeutral(device) && Clock::now() - start < std::chrono::seconds(3))
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  return std::chrono::duration_cast<std::chrono::milliseconds>(Clock::now() - start);
}

std::filesystem::path shotPath(const std::string& name) {
  return std::filesystem::path(WIRCAM_SCREENSHOT_DIR) / name;
}

SignedInPage::SignedInPage(uint16_t port, std::vector<std::string> extra,
                           const std::string& profile, bool withToken)
    : recorder(port, withArgs(std::move(extra), withToken)) {
  auto found = recorder.waitForLog("http://", std::chrono::milliseconds(10000));
  EXPECT_TRUE(found) << recorder.log();
  url = found.value_or("");
  page = DevToolsPage::launch(shotPath(profile), 900, 1400);
  EXPECT_TRUE(page);
  if (!page) return;
  if (withToken) {
    EXPECT_TRUE(page->setCookie("wircam_token", kToken, url));
  }
  EXPECT_TRUE(page->navigate(url));
}

std::pair<double, double> SignedInPage::centreOf(const std::string& selector) {
  auto box = page->evaluate("(() => { const r = document.querySelector('" + selector +
                            "').getBoundingClientRect(); return [r.x + r.width / 2, "
                            "r.y + r.height / 2]; })()");
  if (!box.is_array()) return {0, 0};
  return {box[0].get<double>(), box[1].get<double>()};
}

void SignedInPage::clickOn(const std::string& selector) {
  page->evaluate("document.querySelector('" + selector + "').scrollIntoView({block: 'center'})");
  auto [x, y] = centreOf(selector);
  page->click(x, y);
}

}  // namespace wircam::testing
