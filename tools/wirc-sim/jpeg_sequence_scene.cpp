#include "jpeg_sequence_scene.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>

namespace wircam::sim {

JpegSequenceScene::JpegSequenceScene(std::vector<std::vector<uint8_t>> frames)
    : frames_(std::move(frames)) {}

Expected<std::vector<std::vector<uint8_t>>, std::string> JpegSequenceScene::loadFolder(
    const std::string& directory) {
  namespace fs = std::filesystem;
  std::error_code error;
  std::vector<fs::path> paths;
  for (const auto& entry : fs::directory_iterator(directory, error)) {
    auto extension = entry.path().extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(), ::tolower);
    if (entry.is_regular_file() && (extension == ".jpg" || extension == ".jpeg"))
      paths.push_back(entry.path());
  }
  if (error) return unexpected("cannot read folder '" + directory + "': " + error.message());
  if (paths.empty()) return unexpected("no .jpg or .jpeg files in '" + directory + "'");
  std::sort(paths.begin(), paths.end());
  std::vector<std::vector<uint8_t>> frames;
  for (const auto& path : paths) {
    std::ifstream file(path, std::ios::binary);
    std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(file)), {});
    if (!file.good() && !file.eof()) return unexpected("cannot read '" + path.string() + "'");
    if (bytes.size() < 4 || bytes[0] != 0xFF || bytes[1] != 0xD8)
      return unexpected("'" + path.string() + "' is not a JPEG file (no SOI marker)");
    frames.push_back(std::move(bytes));
  }
  return frames;
}

void JpegSequenceScene::advance(wirc::DeviceClock::time_point, const wirc::ChannelOutputs&) {}

std::vector<uint8_t> JpegSequenceScene::renderJpeg(int camera) {
  if (frames_.empty()) return {};
  size_t& next = next_[camera];
  const auto& frame = frames_[next];
  next = (next + 1) % frames_.size();
  return frame;
}

}  // namespace wircam::sim
