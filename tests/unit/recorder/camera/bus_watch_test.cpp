// The cameras' bus watches: each bus's messages reach its handler on the
// main loop in the order posted, from any thread, through one source that
// polls one descriptor however many buses it watches; a watch
// gone (or a handler that says FALSE) hears no more, and a message not
// delivered yet can be taken out.
#include "camera/bus_watch.h"

#include <gst/gst.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "main_loop_until.h"

namespace {

using wircam::recorder::BusWatch;
using wircam::testing::runMainLoopUntil;

GstMessage* numbered(GstBus* bus, int number) {
  return gst_message_new_element(
      GST_OBJECT(bus), gst_structure_new("numbered", "number", G_TYPE_INT, number, nullptr));
}

int numberOf(GstMessage* message) {
  int number = -1;
  gst_structure_get_int(gst_message_get_structure(message), "number", &number);
  return number;
}

// What one watch delivered, and on which thread.
struct Heard {
  std::vector<int> numbers;
  bool offTheMainThread = false;
  bool keepListening = true;
  std::unique_ptr<BusWatch>* ownWatch = nullptr;  // destroyed by its first message, if set

  static gboolean onMessage(GstBus*, GstMessage* message, gpointer data) {
    auto* heard = static_cast<Heard*>(data);
    heard->numbers.push_back(numberOf(message));
    if (!g_main_context_is_owner(g_main_context_default())) heard->offTheMainThread = true;
    if (heard->ownWatch) heard->ownWatch->reset();
    return heard->keepListening;
  }
};

// How many descriptors the default main context polls now.
int descriptorsPolled() {
  GMainContext* context = g_main_context_default();
  EXPECT_TRUE(g_main_context_acquire(context));
  gint priority = 0;
  g_main_context_prepare(context, &priority);
  gint timeout = 0;
  std::vector<GPollFD> fds(1024);
  gint count =
      g_main_context_query(context, priority, &timeout, fds.data(), static_cast<gint>(fds.size()));
  g_main_context_check(context, priority, fds.data(), std::min<gint>(count, fds.size()));
  g_main_context_release(context);
  return count;
}

class BusWatchTest : public ::testing::Test {
 protected:
  void SetUp() override { gst_init(nullptr, nullptr); }
  void TearDown() override {
    for (GstBus* bus : buses_) gst_object_unref(bus);
  }
  GstBus* newBus() { return buses_.emplace_back(gst_bus_new()); }
  // Runs the loop until nothing is ready (what was posted is delivered).
  static void deliverAll() {
    while (g_main_context_iteration(nullptr, FALSE)) {
    }
  }

 private:
  std::vector<GstBus*> buses_;
};

TEST_F(BusWatchTest, DeliversEachBusInTheOrderPostedOnTheMainLoopFromAnyThread) {
  constexpr int kBuses = 4, kMessages = 200;
  std::vector<Heard> heard(kBuses);
  std::vector<std::unique_ptr<BusWatch>> watches;
  std::vector<std::thread> posters;
  for (int b = 0; b < kBuses; ++b) {
    GstBus* bus = newBus();
    watches.push_back(std::make_unique<BusWatch>(bus, Heard::onMessage, &heard[b]));
    posters.emplace_back([bus] {
      for (int i = 0; i < kMessages; ++i) gst_bus_post(bus, numbered(bus, i));
    });
  }
  ASSERT_TRUE(runMainLoopUntil([&] {
    for (const auto& h : heard)
      if (h.numbers.size() < kMessages) return false;
    return true;
  }));
  for (auto& poster : posters) poster.join();
  std::vector<int> inOrder(kMessages);
  for (int i = 0; i < kMessages; ++i) inOrder[i] = i;
  for (const auto& h : heard) {
    EXPECT_EQ(h.numbers, inOrder);
    EXPECT_FALSE(h.offTheMainThread);
  }
}

TEST_F(BusWatchTest, PollsOneDescriptorForAllBusesAndDeliversAllThatWaitsInOneTurn) {
  int none = descriptorsPolled();
  constexpr int kBuses = 64;
  std::vector<Heard> heard(kBuses);
  std::vector<std::unique_ptr<BusWatch>> watches;
  for (int b = 0; b < kBuses; ++b) {
    GstBus* bus = newBus();
    watches.push_back(std::make_unique<BusWatch>(bus, Heard::onMessage, &heard[b]));
    for (int i = 0; i < 3; ++i) gst_bus_post(bus, numbered(bus, i));
  }
  // (The shared one is made by the first watch of the process, which may
  // have been an earlier test's.)
  EXPECT_LE(descriptorsPolled(), none + 1);
  // (A bus watch of each bus's own takes a turn of the loop a message.)
  EXPECT_TRUE(g_main_context_iteration(nullptr, FALSE));
  for (const auto& h : heard) EXPECT_EQ(h.numbers, (std::vector<int>{0, 1, 2}));
  // Nothing left to make the loop turn again.
  EXPECT_FALSE(g_main_context_iteration(nullptr, FALSE));
}

TEST_F(BusWatchTest, AWatchGoneHearsNothingItsBusPostedBeforeOrAfter) {
  GstBus* bus = newBus();
  Heard first, second;
  auto watch = std::make_unique<BusWatch>(bus, Heard::onMessage, &first);
  gst_bus_post(bus, numbered(bus, 1));
  watch.reset();
  gst_bus_post(bus, numbered(bus, 2));  // to the bus's own queue: nobody watches
  deliverAll();
  EXPECT_TRUE(first.numbers.empty());
  // The bus can be watched again.
  gst_bus_set_flushing(bus, TRUE);
  gst_bus_set_flushing(bus, FALSE);
  watch = std::make_unique<BusWatch>(bus, Heard::onMessage, &second);
  gst_bus_post(bus, numbered(bus, 3));
  deliverAll();
  EXPECT_EQ(second.numbers, std::vector<int>{3});
}

TEST_F(BusWatchTest, AHandlerThatSaysFalseOrDestroysItsWatchHearsNoMore) {
  GstBus* saysFalse = newBus();
  GstBus* destroys = newBus();
  Heard once{.keepListening = false}, destroyed;
  BusWatch falseWatch(saysFalse, Heard::onMessage, &once);
  auto ownWatch = std::make_unique<BusWatch>(destroys, Heard::onMessage, &destroyed);
  destroyed.ownWatch = &ownWatch;
  for (int i = 0; i < 3; ++i) {
    gst_bus_post(saysFalse, numbered(saysFalse, i));
    gst_bus_post(destroys, numbered(destroys, i));
  }
  deliverAll();
  gst_bus_post(saysFalse, numbered(saysFalse, 9));
  deliverAll();
  EXPECT_EQ(once.numbers, std::vector<int>{0});
  EXPECT_EQ(destroyed.numbers, std::vector<int>{0});
  EXPECT_EQ(ownWatch, nullptr);
}

TEST_F(BusWatchTest, TakesAMessageOfAKindBeforeItIsDelivered) {
  GstBus* bus = newBus();
  Heard heard;
  BusWatch watch(bus, Heard::onMessage, &heard);
  EXPECT_EQ(watch.take(GST_MESSAGE_ERROR), nullptr);
  gst_bus_post(bus, numbered(bus, 1));
  GError* error = g_error_new_literal(GST_CORE_ERROR, GST_CORE_ERROR_FAILED, "cannot start");
  gst_bus_post(bus, gst_message_new_error(GST_OBJECT(bus), error, nullptr));
  g_error_free(error);
  gst_bus_post(bus, numbered(bus, 2));
  GstMessage* taken = watch.take(GST_MESSAGE_ERROR);
  ASSERT_NE(taken, nullptr);
  GError* said = nullptr;
  gst_message_parse_error(taken, &said, nullptr);
  EXPECT_STREQ(said->message, "cannot start");
  g_error_free(said);
  gst_message_unref(taken);
  deliverAll();
  EXPECT_EQ(heard.numbers, (std::vector<int>{1, 2}));  // the error was not delivered
}

}  // namespace
