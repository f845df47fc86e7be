#include "headless_chromium.h"

#include <gst/app/gstappsink.h>
#include <gst/video/video.h>
#include <unistd.h>

#include <cstdlib>

#include "gst_scoped.h"

namespace wircam::testing {

bool chromiumInstalled() { return std::system("command -v chromium > /dev/null") == 0; }

std::filesystem::path processProfile(const std::filesystem::path& base) {
  return base.string() + "-" + std::to_string(getpid());
}

std::vector<std::string> chromiumFlags(const std::filesystem::path& profile, int width,
                                       int height) {
  return {"--headless",
          "--no-sandbox",
          "--disable-gpu",
          "--disable-dev-shm-usage",
          "--disable-quic",
          "--no-first-run",
          "--disable-background-networking",
          "--disable-component-update",
          "--disable-sync",
          "--user-data-dir=" + profile.string(),
          "--window-size=" + std::to_string(width) + "," + std::to_string(height)};
}

bool screenshot(const std::string& url, const std::filesystem::path& shot, int width, int height,
                int budgetMs) {
  auto profile = processProfile(shot.parent_path() / (shot.stem().string() + "-chromium-profile"));
  std::string command = "timeout 60 chromium";
  for (const auto& flag : chromiumFlags(profile, width, height)) command += " " + flag;
  command += (budgetMs > 0 ? " --virtual-time-budget=" + std::to_string(budgetMs) : "") +
             " --timeout=10000 --screenshot=" + shot.string() + " " + url + " > /dev/null 2>&1";
  bool taken = std::system(command.c_str()) == 0;
  std::error_code ignored;
  std::filesystem::remove_all(profile, ignored);
  return taken;
}

int Picture::count(uint8_t r, uint8_t g, uint8_t b, int tolerance) const {
  int n = 0;
  for (size_t i = 0; i + 2 < rgb.size(); i += 3)
    if (std::abs(rgb[i] - r) <= tolerance && std::abs(rgb[i + 1] - g) <= tolerance &&
        std::abs(rgb[i + 2] - b) <= tolerance)
      ++n;
  return n;
}

Picture readPng(const std::filesystem::path& file) {
  std::string description = "filesrc location=\"" + file.string() +
                            "\" ! pngdec ! videoconvert ! video/x-raw,format=RGB ! "
                            "appsink name=sink";
  GstElement* pipeline = gst_parse_launch(description.c_str(), nullptr);
  GstElement* sink = gst_bin_get_by_name(GST_BIN(pipeline), "sink");
  gst_element_set_state(pipeline, GST_STATE_PLAYING);
  Picture picture;
  if (GstSample* sample = gst_app_sink_try_pull_sample(GST_APP_SINK(sink), 10 * GST_SECOND)) {
    GstVideoInfo info;
    gst_video_info_from_caps(&info, gst_sample_get_caps(sample));
    picture.width = GST_VIDEO_INFO_WIDTH(&info);
    picture.height = GST_VIDEO_INFO_HEIGHT(&info);
    {
      gst::ScopedBufferMap map(gst_sample_get_buffer(sample), GST_MAP_READ);
      int stride = GST_VIDEO_INFO_PLANE_STRIDE(&info, 0);
      for (int y = 0; y < picture.height && map; ++y)
        picture.rgb.insert(picture.rgb.end(), map.data() + y * stride,
                           map.data() + y * stride + picture.width * 3);
    }
    gst_sample_unref(sample);
  }
  gst_element_set_state(pipeline, GST_STATE_NULL);
  gst_object_unref(sink);
  gst_object_unref(pipeline);
  return picture;
}

}  // namespace wircam::testing
