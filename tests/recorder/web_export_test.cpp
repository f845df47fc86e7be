// The day's timeline in a real browser (Debian's chromium over the DevTools
// protocol): it spans the camera's segments with their detections, a click
// plays from that moment on across a segment boundary, and a range dragged
// on it downloads as a file that plays. The screenshot and the download
// stay under the build tree (build/tests/recorder/web-export*).
#include <gtest/gtest.h>

#include <algorithm>
#include <nlohmann/json.hpp>

#include "camera_checks.h"
#include "headless_chromium.h"
#include "recorder_process.h"
#include "shell_command.h"
#include "signed_in_page.h"
#include "wait_for.h"

namespace {

namespace fs = std::filesystem;
using namespace wircam::testing;
using std::chrono::milliseconds;

// The finished download in `folder` (Chromium writes a .crdownload first).
std::optional<fs::path> downloaded(const fs::path& folder, const std::string& extension) {
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(folder, error))
    if (entry.path().extension() == extension) return entry.path();
  return std::nullopt;
}

TEST(WebExport, TheDaysTimelinePlaysAcrossSegmentsAndARangeDownloadsAsAFileThatPlays) {
  if (!chromiumInstalled()) GTEST_SKIP() << "chromium is not installed";
  FollowedCar car;
  ASSERT_TRUE(car.device);
  SignedInPage signedIn(car.device->port(), {"--detect", "tag36h11", "--follow", "--segment", "2"},
                        "web-export");
  ASSERT_TRUE(signedIn.page);
  auto& page = *signedIn.page;
  ASSERT_TRUE(page.waitUntil("document.querySelectorAll('#recordings tr').length >= 3",
                             milliseconds(20000)));
  fs::path downloads = shotPath("web-export-downloads");
  fs::remove_all(downloads);
  fs::create_directories(downloads);
  ASSERT_TRUE(page.allowDownloads(downloads));

  // A point at a fraction of the timeline's time axis, in its segments'
  // row, once it is scrolled into view (the player opening moves it).
  auto pointAt = [&](double fraction) -> std::pair<double, double> {
    page.evaluate(
        "document.querySelector('canvas.day-timeline').scrollIntoView({block: 'center'})");
    auto box = page.evaluate(
        "(() => { const r = document.querySelector('canvas.day-timeline')"
        ".getBoundingClientRect(); return [r.x, r.y, r.width, dayLeft, dayRight]; })()");
    if (!box.is_array()) return {0, 0};
    double left = box[0], top = box[1], width = box[2], marginLeft = box[3], marginRight = box[4];
    return {left + marginLeft + fraction * (width - marginLeft - marginRight), top + 10};
  };

  // A click near the start plays that segment, and then the next.
  auto [clickX, clickY] = pointAt(0.05);
  page.click(clickX, clickY);
  ASSERT_TRUE(page.waitUntil("!document.getElementById('player').hidden && player.file"));
  std::string first = page.evaluate("player.file");
  EXPECT_TRUE(page.waitUntil("player.file !== '" + first + "'", milliseconds(8000)))
      << "still on " << first;

  // A drag selects a range; it offers the formats the recording can take.
  // The page moves while the recording goes on (a row for each new
  // segment): on a loaded machine a drag made where the timeline was a
  // moment before once missed it. Made again where it is, up to three times.
  bool selected = false;
  for (int attempt = 0; attempt < 3 && !selected; ++attempt) {
    auto [fromX, fromY] = pointAt(0.2);
    auto [toX, toY] = pointAt(0.8);
    page.drag(fromX, fromY, toX, toY);
    selected =
        page.waitUntil("document.querySelector('a.export[data-format=mkv]')", milliseconds(4000));
  }
  ASSERT_TRUE(selected);
  EXPECT_TRUE(page.evaluate("document.querySelector('a.export[data-format=mcap]') !== null"));
  EXPECT_TRUE(page.evaluate("document.querySelector('a.export[data-format=mp4]') === null"))
      << "JPEG recordings cannot go into MP4";
  auto shot = shotPath("web-export.png");
  ASSERT_TRUE(page.screenshot(shot));
  EXPECT_GT(readPng(shot).count(0x00, 0xc8, 0x53, 12), 20) << "detection ticks";

  // (Under load a segment closing adds a row to the list between finding
  // the link and the click: clickOn makes a missed click again.)
  ASSERT_TRUE(signedIn.clickOn("a.export[data-format=mkv]"));
  ASSERT_TRUE(
      waitFor([&] { return downloaded(downloads, ".mkv").has_value(); }, milliseconds(20000)));
  fs::path file = *downloaded(downloads, ".mkv");
  EXPECT_EQ(file.filename().string().find(cameraName(car.device->port()) + "_"), 0u) << file;
  // It plays: every frame decodes, and they are the recorded ones, a run of
  // them from the middle of the recording.
  EXPECT_EQ(ffmpegDecodeErrors(file), "");
  auto exported = frameDigests(file);
  ASSERT_GT(exported.size(), 10u);
  std::vector<std::string> recorded;
  for (const auto& segment : signedIn.recorder.files(".mkv"))
    for (auto& digest : frameDigests(segment)) recorded.push_back(digest);
  EXPECT_LT(exported.size(), recorded.size());
  EXPECT_NE(std::search(recorded.begin(), recorded.end(), exported.begin(), exported.end()),
            recorded.end());
}

}  // namespace
