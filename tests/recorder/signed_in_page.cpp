#include "signed_in_page.h"

#include <gtest/gtest.h>

#include <iostream>
#include <thread>

#include "wait_for.h"

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

void expectJunkStopsTheCarAtOnce(DevToolsPage& page, const wirc::Device& device) {
  page.evaluate(
      "window.keep = setInterval(() => probe.send(JSON.stringify({seq: 1, steering: 0, "
      "throttle: 1})), 100)");
  ASSERT_TRUE(waitFor([&] { return device.outputs().pulses[kThrottle] > 1500; }));
  ASSERT_TRUE(page.waitUntil("window.answer && window.answer.ack === 1"));
  // A good command and the junk in one task, timed from before it: the
  // dead-man cannot lapse sooner than 250 ms after the good command was
  // sent, so neutral sooner is the junk's doing, however loaded the machine
  // (page, recorder and device all run late together).
  auto sent = std::chrono::steady_clock::now();
  page.evaluate(
      "clearInterval(keep); probe.send(JSON.stringify({seq: 2, steering: 0, throttle: 1})); "
      "probe.send('{\"steering\": \"hard left\"}')");
  untilNeutral(device);
  auto neutral = std::chrono::duration_cast<std::chrono::milliseconds>(
      std::chrono::steady_clock::now() - sent);
  EXPECT_LT(neutral.count(), 250) << "neutral " << neutral.count() << " ms after the junk";
  ASSERT_TRUE(page.waitUntil("window.answer.error"));
  EXPECT_EQ(page.evaluate("window.answer.error"), "'steering' is not a number");
  EXPECT_EQ(page.evaluate("window.answer.neutral"), true);
}

void expectAHungPageStopsTheCar(DevToolsPage& page, const wirc::Device& device) {
  page.pauseScripts();
  auto hung = untilNeutral(device);
  EXPECT_LE(hung.count(), 250 + 100 + 100) << "neutral " << hung.count() << " ms after the hang";
  std::cerr << "[ measured ] hung page → neutral in " << hung.count() << " ms\n";
}

void expectAClosedTabStopsTheCar(DevToolsPage& page, const wirc::Device& device) {
  page.call("Debugger.resume");
  ASSERT_TRUE(waitFor([&] { return device.outputs().pulses[kThrottle] > 1500; }));
  page.closeTab();
  auto closed = untilNeutral(device);
  EXPECT_LE(closed.count(), 250 + 100) << "neutral " << closed.count() << " ms after closing";
  std::cerr << "[ measured ] closed tab → neutral in " << closed.count() << " ms\n";
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
