// LinkListeners: a listener added late still learns the link's state and
// control right, exactly once, however add() and the events interleave.
#include <gtest/gtest.h>

#include <atomic>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "link/vehicle_link.h"

namespace wircam::link {
namespace {

// What one listener heard, in order, described.
struct Heard {
  std::mutex mutex;
  std::vector<std::string> events;
  LinkListeners::Listener listener() {
    return [this](const LinkEvent& event) {
      std::lock_guard lock(mutex);
      events.push_back(describe(event));
    };
  }
};

TEST(LinkListeners, AListenerAddedAfterTheLoginHearsTheStateAndControlRightFirst) {
  LinkListeners listeners;
  listeners.emit(StateChanged{LinkState::Live, "logged in"});
  listeners.emit(TelemetryReceived{});
  listeners.emit(ControlRightChanged{true, ""});
  Heard late;
  int id = listeners.add(late.listener());
  EXPECT_EQ(late.events,
            (std::vector<std::string>{"link live: logged in", "control right granted"}));
  listeners.emit(StateChanged{LinkState::Lost, "timeout"});
  listeners.remove(id);
  listeners.emit(StateChanged{LinkState::Live, "again"});
  EXPECT_EQ(late.events, (std::vector<std::string>{"link live: logged in", "control right granted",
                                                   "link lost: timeout"}));
}

TEST(LinkListeners, OnlyTheLastStateIsReplayedAndNothingBeforeTheFirstEvent) {
  LinkListeners listeners;
  Heard early;
  listeners.add(early.listener());
  EXPECT_TRUE(early.events.empty());
  listeners.emit(StateChanged{LinkState::Live, "first"});
  listeners.emit(StateChanged{LinkState::Lost, "gone"});
  Heard late;
  listeners.add(late.listener());
  EXPECT_EQ(late.events, std::vector<std::string>{"link lost: gone"});
  EXPECT_EQ(early.events.size(), 2u);
}

// Listeners added while another thread emits states: each hears the state
// in force when it joined and every later one, in order, none twice.
TEST(LinkListeners, AListenerAddedDuringEventsMissesNoneAndHearsNoneTwice) {
  constexpr int kListeners = 300;
  LinkListeners listeners;
  std::atomic<int> emitted{0};
  std::atomic<bool> allAdded{false};
  // States go on until every listener joined, so each joins mid-stream.
  std::thread emitter([&] {
    for (int i = 0; !allAdded || i < 10; ++i) {
      listeners.emit(StateChanged{i % 2 ? LinkState::Lost : LinkState::Live, std::to_string(i)});
      emitted = i + 1;
    }
  });
  struct Joined {
    int emittedBefore = 0;
    std::mutex mutex;
    std::vector<int> states;
  };
  std::vector<std::unique_ptr<Joined>> joined;
  std::vector<int> ids;
  for (int n = 0; n < kListeners; ++n) {
    auto& one = *joined.emplace_back(std::make_unique<Joined>());
    one.emittedBefore = emitted;
    ids.push_back(listeners.add([&one](const LinkEvent& event) {
      std::lock_guard lock(one.mutex);
      one.states.push_back(std::stoi(std::get<StateChanged>(event).reason));
    }));
    std::this_thread::yield();
  }
  allAdded = true;
  emitter.join();
  for (const auto& one : joined) {
    ASSERT_FALSE(one->states.empty());
    // The first heard is the state in force at add(): not older than the
    // last one emitted before add() began.
    EXPECT_GE(one->states.front(), one->emittedBefore - 1);
    for (size_t i = 1; i < one->states.size(); ++i)
      ASSERT_EQ(one->states[i], one->states[i - 1] + 1) << "a state missed or heard twice";
    EXPECT_EQ(one->states.back(), emitted - 1);
  }
  for (int id : ids) listeners.remove(id);
}

}  // namespace
}  // namespace wircam::link
