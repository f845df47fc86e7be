#include "replay/replay_scene.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <nlohmann/json.hpp>

namespace wircam::sim {

using std::chrono::duration_cast;
using std::chrono::nanoseconds;

namespace {

// Between two frames when there is no next one to time it by.
constexpr auto kIdleTick = std::chrono::milliseconds(100);

}  // namespace

ReplayScene::ReplayScene(std::unique_ptr<RecordedDrive> drive, Options options)
    : drive_(std::move(drive)), options_(std::move(options)) {}

Expected<std::unique_ptr<ReplayScene>, std::string> ReplayScene::create(
    std::unique_ptr<RecordedDrive> drive, Options options) {
  if (!(options.speed > 0)) return unexpected(std::string("--speed must be above 0"));
  std::unique_ptr<ReplayScene> scene(new ReplayScene(std::move(drive), std::move(options)));
  if (!scene->options_.commandsOut.empty()) {
    scene->commands_ = std::fopen(scene->options_.commandsOut.c_str(), "w");
    if (!scene->commands_)
      return unexpected("cannot write " + scene->options_.commandsOut + ": " +
                        std::strerror(errno));
  }
  scene->coming_ = scene->drive_->next();
  scene->sayNotes();
  return scene;
}

ReplayScene::~ReplayScene() {
  if (commands_) std::fclose(commands_);
}

void ReplayScene::sayNotes() {
  for (const auto& note : drive_->takeNotes())
    if (options_.log) options_.log(note);
}

void ReplayScene::advance(wirc::DeviceClock::time_point now, const wirc::ChannelOutputs&) {
  if (!started_) started_ = now;
  shown_ = std::move(coming_);
  coming_ = drive_->next();
  if (!coming_ && shown_ && options_.loop) {
    drive_->rewind();
    ++loops_;
    coming_ = drive_->next();
  }
  sayNotes();
  if (shown_) {
    ++framesShown_;
  } else if (!endSaid_) {
    endSaid_ = true;
    if (options_.ended) options_.ended();
  }
}

std::vector<uint8_t> ReplayScene::renderJpeg(int camera) {
  if (camera != 0 || !shown_) return {};
  return shown_->jpeg;
}

std::optional<wirc::DeviceClock::duration> ReplayScene::frameInterval() {
  if (!shown_ || !coming_) return kIdleTick;
  int64_t gap = coming_->timeNs - shown_->timeNs;
  if (gap < 0) gap = 0;  // back to the start (--loop): the next frame at once
  if (gap > duration_cast<nanoseconds>(kMaxGap).count()) {
    if (options_.log)
      options_.log("a pause of " + std::to_string(gap / 1000000000) + " s before " +
                   coming_->segment + " replayed as " + std::to_string(kMaxGap.count()) + " s");
    gap = duration_cast<nanoseconds>(kMaxGap).count();
  }
  return duration_cast<wirc::DeviceClock::duration>(
      nanoseconds(static_cast<int64_t>(static_cast<double>(gap) / options_.speed)));
}

std::optional<uint16_t> ReplayScene::batteryMillivolts() {
  return drive_->batteryMillivoltsAt(shown_ ? shown_->timeNs : 0);
}

void ReplayScene::pcdReceived(wirc::DeviceClock::time_point at, const wirc::ChannelValues& values) {
  if (!commands_ || !shown_ || !started_) return;
  nlohmann::json line = {
      {"frame", shown_->index},
      {"pts", shown_->ptsNs},
      {"segment", shown_->segment},
      {"channels", values},
      {"arrival_ms", std::chrono::duration<double, std::milli>(at - *started_).count()}};
  // A line at a time, flushed: a replay stopped by a signal keeps them all.
  std::fputs((line.dump() + "\n").c_str(), commands_);
  std::fflush(commands_);
  ++commandsWritten_;
}

std::string ReplayScene::summary() const {
  std::string text = "replayed " + std::to_string(framesShown_) + " frames of " +
                     std::to_string(drive_->segments()) + " segment" +
                     (drive_->segments() == 1 ? "" : "s") + " (" + drive_->camera() + ")";
  if (loops_) text += ", " + std::to_string(loops_ + 1) + " times";
  for (const auto& damage : drive_->damage()) text += "; " + damage;
  if (commands_)
    text += ", " + std::to_string(commandsWritten_) + " PCD written to " + options_.commandsOut;
  return text;
}

}  // namespace wircam::sim
