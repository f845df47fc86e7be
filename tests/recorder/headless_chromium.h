// Debian's chromium, headless, as the tests' real browser: a screenshot of a
// page (kept under the build tree for people to look at) and its pixels.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace wircam::testing {

bool chromiumInstalled();

// `base` made this process's own: a second Chromium on a profile in use
// hands its URL to the first and exits, so two runs of one test at once
// would fail each other.
std::filesystem::path processProfile(const std::filesystem::path& base);

// The flags every test run of chromium gets: headless, a fresh profile
// in `profile`, nothing fetched from the network, the window's size.
std::vector<std::string> chromiumFlags(const std::filesystem::path& profile, int width, int height);

// Loads `url` in a window of width×height and saves a PNG to `shot` once
// it has loaded, or (budgetMs > 0) after its scripts had that much virtual
// time; false if it failed.
bool screenshot(const std::string& url, const std::filesystem::path& shot, int width, int height,
                int budgetMs = 0);

// Pixels of a PNG as RGB, decoded by GStreamer's pngdec.
struct Picture {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;
  // How many pixels are within `tolerance` of the colour in each channel.
  int count(uint8_t r, uint8_t g, uint8_t b, int tolerance) const;
};
Picture readPng(const std::filesystem::path& file);

}  // namespace wircam::testing
