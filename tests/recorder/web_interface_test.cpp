// The live view page in a real browser (Debian's chromium over the
// DevTools protocol) as its users use it: a recording plays and its time
// advances, its telemetry timeline is drawn and a click on it seeks; drive
// mode moves the simulated car with the arrow keys and a page that hangs
// or goes away stops it; without the token, control is refused. The
// screenshots stay under the build tree (build/tests/recorder/web-*.png).
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <thread>

#include "devtools_page.h"
#include "follow_scene.h"
#include "headless_chromium.h"
#include "http_fetch.h"
#include "recorder_process.h"
#include "signed_in_page.h"
#include "simulated_device.h"
#include "wait_for.h"

namespace {

using namespace wircam;
using namespace wircam::testing;
using std::chrono::milliseconds;
using Clock = std::chrono::steady_clock;

double shownPosition(DevToolsPage& page) {
  auto text = page.evaluate("document.getElementById('playback-time').textContent");
  return text.is_string() ? std::atof(text.get<std::string>().c_str()) : -1;
}

TEST(WebInterface, ARecordingPlaysItsTimeAdvancesAndATimelineClickSeeks) {
  if (!chromiumInstalled()) GTEST_SKIP() << "chromium is not installed";
  FollowedCar car;
  ASSERT_TRUE(car.device);
  SignedInPage signedIn(car.device->port(), {"--detect", "tag36h11", "--follow", "--segment", "6"},
                        "web-playback");
  ASSERT_TRUE(signedIn.page);
  auto& page = *signedIn.page;
  // A finished segment in the list, then play it.
  ASSERT_TRUE(page.waitUntil("document.querySelector('button.play')", milliseconds(20000)));
  auto pressed = Clock::now();
  ASSERT_TRUE(signedIn.clickOn("button.play"));
  ASSERT_TRUE(page.waitUntil("!document.getElementById('player').hidden"));

  // It plays at real speed: the shown time advances with the clock.
  ASSERT_TRUE(
      page.waitUntil("parseFloat(document.getElementById('playback-time').textContent) "
                     "> 0.3"));
  // It plays in time: never more of the recording than the time since
  // play was pressed (a loaded machine may hold frames back and then show
  // them at once: a second in 0.42 s, after such a pause), and two seconds
  // of it within 6 s (a shorter span in three times its length), which a
  // stall or a third of real speed would not make. The player keeps time
  // by the pipeline clock; how late the page shows the frames is the
  // browser's share of the machine: two seconds took 3.9 s in a fresh root
  // beside seven suites (a speed is for a benchmark to measure, not a
  // timed test).
  double first = shownPosition(page);
  // Two seconds, or what the segment has left: the first one may be short
  // (segments are cut on the clock's multiples of --segment), and a span
  // past its end never comes (15 s waited in vain beside a build).
  double length = page.evaluate("player.duration").get<double>();
  double span = std::min(2.0, length - first - 0.2);
  ASSERT_GT(span, 0.3) << "the segment is " << length << " s, shown at " << first;
  auto started = Clock::now();
  ASSERT_TRUE(
      page.waitUntil("parseFloat(document.getElementById('playback-time').textContent) "
                     ">= " +
                         std::to_string(first + span),
                     milliseconds(15000)))
      << "from " << first << " s, " << span
      << " s on: " << page.evaluate("document.getElementById('playback-time').textContent").dump();
  auto took = std::chrono::duration<double>(Clock::now() - started).count();
  double shown = shownPosition(page);
  auto sincePressed = std::chrono::duration<double>(Clock::now() - pressed).count();
  EXPECT_LE(shown, sincePressed + 0.1) << "ahead of the clock: " << shown << " s of the recording "
                                       << sincePressed << " s after play was pressed";
  EXPECT_LT(took, 3 * span) << span << " s played in " << took << " s";
  EXPECT_TRUE(page.waitUntil("document.getElementById('playback-image').naturalWidth === 352"));

  // The timeline is drawn from the sidecar: detections (green) and the
  // cursor; the screenshot shows them.
  page.evaluate("document.getElementById('timeline').scrollIntoView({block: 'center'})");
  auto shot = shotPath("web-playback.png");
  ASSERT_TRUE(page.screenshot(shot));
  auto picture = readPng(shot);
  EXPECT_GT(picture.count(0x00, 0xc8, 0x53, 12), 40) << "detection ticks";
  EXPECT_GT(picture.count(0x0d, 0x0f, 0x12, 2), 5000) << "the timeline's background";

  // A click at 80 % of the timeline seeks there.
  auto box = page.evaluate(
      "(() => { const r = document.getElementById('timeline').getBoundingClientRect(); "
      "return [r.x, r.y, r.width, r.height, player.duration, timelineLeft, timelineRight]; })()");
  ASSERT_TRUE(box.is_array());
  double left = box[0], top = box[1], width = box[2], height = box[3], duration = box[4];
  double marginLeft = box[5], marginRight = box[6];
  page.click(left + marginLeft + 0.8 * (width - marginLeft - marginRight), top + height / 2);
  ASSERT_TRUE(page.waitUntil("player.position >= " + std::to_string(0.8 * duration - 0.3)));
  // ...and plays on from there.
  double afterSeek = shownPosition(page);
  EXPECT_GE(afterSeek, 0.8 * duration - 0.3);
  EXPECT_TRUE(page.waitUntil("player.position > " + std::to_string(afterSeek + 0.2)));
  page.screenshot(shotPath("web-playback-seeked.png"));

  // The files themselves answer Range requests, so an MP4 seeks in <video>.
  std::string file = page.evaluate("player.file");
  auto part = fetch(signedIn.url + "recordings/" + file, "GET",
                    {{"Authorization", std::string("Bearer ") + kToken}, {"Range", "bytes=0-99"}});
  EXPECT_EQ(part.status, 206u);
  EXPECT_EQ(part.body.size(), 100u);

  // At a phone's width nothing runs off the side.
  page.call("Emulation.setDeviceMetricsOverride",
            {{"width", 390}, {"height", 844}, {"deviceScaleFactor", 2}, {"mobile", true}});
  EXPECT_TRUE(page.waitUntil("document.documentElement.scrollWidth <= 390"))
      << page.evaluate("document.documentElement.scrollWidth");
  page.screenshot(shotPath("web-phone.png"));
}

TEST(WebInterface, DriveModeMovesTheCarAndAPageThatHangsOrGoesAwayStopsIt) {
  if (!chromiumInstalled()) GTEST_SKIP() << "chromium is not installed";
  FollowedCar car;
  ASSERT_TRUE(car.device);
  SignedInPage signedIn(car.device->port(), {"--detect", "tag36h11", "--follow"}, "web-drive");
  ASSERT_TRUE(signedIn.page);
  auto& page = *signedIn.page;
  ASSERT_TRUE(page.waitUntil("document.querySelector('.camera[data-state=live] button.drive')"));
  ASSERT_TRUE(signedIn.clickOn("button.drive"));
  ASSERT_TRUE(
      page.waitUntil("document.querySelector('.drive-info').textContent.startsWith('round trip')"))
      << page.evaluate(
             "document.querySelector('.control-message').textContent + ' | ' + "
             "document.querySelector('.drive-info').textContent + ' | ' + "
             "document.querySelector('.camera').dataset.driveLink");
  // Following went off when drive mode began.
  EXPECT_EQ(page.evaluate("document.querySelector('button.follow').textContent"), "following: off");

  auto before = car.scene->truthNow().car;
  page.key("keyDown", "ArrowUp");
  page.key("keyDown", "ArrowLeft");
  ASSERT_TRUE(waitFor([&] {
    auto pulses = car.device->outputs().pulses;
    return pulses[kThrottle] > 1500 && pulses[kSteering] > 1500;
  }));
  // The car drives forward and to the left for as long as the keys are held.
  waitFor([&] {
    auto now = car.scene->truthNow().car;
    return std::hypot(now.x - before.x, now.y - before.y) > 0.1 && now.theta > before.theta;
  });
  auto after = car.scene->truthNow().car;
  EXPECT_GT(std::hypot(after.x - before.x, after.y - before.y), 0.1) << "the car moved";
  EXPECT_GT(after.theta, before.theta) << "and turned left";
  // The round trip shows, in milliseconds, a new one ten times a second:
  // one under 250 ms within a few of them (a single one, read once, was
  // 260 ms on the loaded machine; performance.md has the idle figures).
  const std::string shown = "Number(document.querySelector('.drive-info').dataset.roundTripMs)";
  EXPECT_TRUE(page.waitUntil(shown + " < 250", std::chrono::milliseconds(2000)))
      << page.evaluate(shown);
  auto roundTrip = page.evaluate(shown);
  ASSERT_TRUE(roundTrip.is_number());
  std::cerr << "[ measured ] drive command round trip " << roundTrip.get<double>() << " ms\n";
  page.screenshot(shotPath("web-drive.png"));

  // The page hangs (its scripts stop, the socket stays open).
  expectAHungPageStopsTheCar(page, *car.device);
  // Counted for Prometheus: at least this lapse (under load the page's
  // 100 ms timer may have run late enough before to let the dead-man lapse).
  std::string lapses = "wircam_drive_deadman_lapses_total{stream=\"127.0.0.1-" +
                       std::to_string(car.device->port()) + "-cam0\"} ";
  std::string metrics;
  EXPECT_TRUE(waitFor([&] {
    metrics =
        fetch(signedIn.url + "metrics", "GET", {{"Authorization", std::string("Bearer ") + kToken}})
            .body;
    auto at = metrics.find(lapses);
    return at != std::string::npos && std::atoi(metrics.c_str() + at + lapses.size()) >= 1;
  })) << metrics;

  expectAClosedTabStopsTheCar(page, *car.device);
}

TEST(WebInterface, AMalformedDriveMessageIsAnsweredAndStopsTheCar) {
  if (!chromiumInstalled()) GTEST_SKIP() << "chromium is not installed";
  FollowedCar car;
  ASSERT_TRUE(car.device);
  SignedInPage signedIn(car.device->port(), {"--detect", "tag36h11", "--follow"}, "web-malformed");
  ASSERT_TRUE(signedIn.page);
  auto& page = *signedIn.page;
  ASSERT_TRUE(page.waitUntil("document.querySelector('.camera[data-state=live]')"));
  std::string camera = "127.0.0.1-" + std::to_string(car.device->port()) + "-cam0";
  // A socket of the page's own (the cookie signs it in), full ahead...
  auto opened = page.evaluate(
      "new Promise(done => { window.probe = new WebSocket(`ws://${location.host}/api/cameras/" +
      camera + "/drive`); probe.onmessage = e => { window.answer = JSON.parse(e.data); }; " +
      "probe.onopen = () => done('open'); probe.onclose = () => done('closed'); })");
  ASSERT_EQ(opened, "open");
  expectJunkStopsTheCarAtOnce(page, *car.device);
}

TEST(WebInterface, WithoutTheTokenControlIsRefused) {
  if (!chromiumInstalled()) GTEST_SKIP() << "chromium is not installed";
  FollowedCar car;
  ASSERT_TRUE(car.device);
  // No token: the page is open (on this machine only), control is not.
  SignedInPage open(car.device->port(), {"--detect", "tag36h11", "--follow"}, "web-refused", false);
  ASSERT_TRUE(open.page);
  auto& page = *open.page;
  ASSERT_TRUE(page.waitUntil("document.querySelector('.camera[data-state=live] button.drive')"));
  ASSERT_TRUE(open.clickOn("button.drive"));
  ASSERT_TRUE(page.waitUntil("document.querySelector('.control-message').textContent"));
  EXPECT_EQ(page.evaluate("document.querySelector('.control-message').textContent"),
            "control needs the recorder started with --http-token (and you signed in)");
  EXPECT_EQ(page.evaluate("document.querySelector('.camera').dataset.driving || 'false'"), "false");
  page.screenshot(shotPath("web-refused.png"));
  // The API says so too, and the drive socket is not opened.
  std::string camera = "127.0.0.1-" + std::to_string(car.device->port()) + "-cam0";
  auto follow = fetch(open.url + "api/cameras/" + camera + "/follow?on=true", "POST");
  EXPECT_EQ(follow.status, 403u);
  EXPECT_EQ(follow.contentType, "application/json");
  auto opened = page.evaluate(
      "new Promise(done => { const s = new WebSocket(`ws://${location.host}/api/cameras/" + camera +
      "/drive`); s.onopen = () => done('open'); s.onclose = () => done('refused'); })");
  EXPECT_EQ(opened, "refused");
  auto drive = fetch(open.url + "api/cameras/" + camera + "/drive");
  EXPECT_EQ(drive.status, 403u);
  // The refused click changed nothing: the recorder still follows.
  auto cameras = nlohmann::json::parse(fetch(open.url + "api/cameras").body);
  EXPECT_EQ(cameras[0]["following"], true);
}

TEST(WebInterface, WithATokenSetControlNeedsIt) {
  FollowedCar car;
  ASSERT_TRUE(car.device);
  RecorderProcess recorder(car.device->port(),
                           {"--detect", "tag36h11", "--follow", "--http", "127.0.0.1:0",
                            "--http-token", kToken, "--duration", "30"});
  auto url = recorder.waitForLog("http://", milliseconds(10000));
  ASSERT_TRUE(url) << recorder.log();
  std::string camera = "127.0.0.1-" + std::to_string(car.device->port()) + "-cam0";
  Headers token = {{"Authorization", std::string("Bearer ") + kToken}};
  EXPECT_EQ(fetch(*url + "api/cameras/" + camera + "/follow?on=false", "POST").status, 401u);
  EXPECT_EQ(fetch(*url + "api/cameras/" + camera + "/drive").status, 401u);
  // With it: following goes off, and /api/cameras says so.
  ASSERT_TRUE(waitFor([&] {
    return fetch(*url + "api/cameras/" + camera + "/follow?on=false", "POST", token).status == 200u;
  }));
  auto cameras = nlohmann::json::parse(fetch(*url + "api/cameras", "GET", token).body);
  EXPECT_EQ(cameras[0]["following"], false);
  auto target = fetch(*url + "api/cameras/" + camera + "/target?id=x", "POST", token);
  EXPECT_EQ(target.status, 400u);
  EXPECT_NE(target.body.find("a target is a tag id 0..65535"), std::string::npos) << target.body;
  EXPECT_EQ(fetch(*url + "api/cameras/nope/follow?on=true", "POST", token).status, 404u);
  EXPECT_EQ(fetch(*url + "api/cameras/" + camera + "/follow?on=true", "GET", token).status, 405u);
  // Drive over the socket without a handshake: not a WebSocket request.
  EXPECT_EQ(fetch(*url + "api/cameras/" + camera + "/drive", "GET", token).status, 400u);
}

}  // namespace
