// The WebRTC service in this process, on a GLib main loop as in the
// recorder: a viewer whose preparation takes long (webrtcbin runs each of its
// operations holding its own lock; the first viewer's includes making the
// DTLS certificate, an RSA key: 0.1-0.4 s on an idle machine, seconds on a
// loaded or small one) never holds the main loop, which serves every
// request and every drive command.
#include "webrtc/webrtc_service.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <optional>

#include "camera/frame_tap.h"
#include "wait_for.h"
#include "whep_offer.h"

namespace {

using namespace wircam;
using namespace wircam::recorder;
using namespace wircam::testing;
using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

// Holds webrtcbin's own thread for `kHeld` when it first adds an element
// of its own (as it sets the viewer's offer): an operation of webrtcbin's
// that takes that long.
constexpr auto kHeld = 2000ms;
GThread* testThread = nullptr;
std::atomic<bool> held{false};

gboolean holdWebrtcbinsOperation(GSignalInvocationHint*, guint, const GValue* values, gpointer) {
  // deep-element-added (bin, the bin the element went into, the element)
  GstElementFactory* into = gst_element_get_factory(GST_ELEMENT(g_value_get_object(&values[1])));
  bool webrtcbins = into && g_str_equal(GST_OBJECT_NAME(into), "webrtcbin");
  if (webrtcbins && g_thread_self() != testThread && !held.exchange(true))
    g_usleep(std::chrono::microseconds(kHeld).count());
  return TRUE;  // stay hooked
}

TEST(WebRtcServiceLoop, AViewerWhosePreparationTakesLongNeverHoldsTheMainLoop) {
  // The process's DTLS certificate made first: the service's wait for it
  // (seconds of a loaded machine) is not what this test holds.
  gst_object_unref(gst_element_factory_make("dtlsdec", nullptr));
  FrameTap frames;  // no frame comes: the answer needs none
  WebRtcService::Settings settings;
  settings.driveMessage = [](const std::string&, std::optional<std::string_view>) {
    return std::string();
  };
  settings.neutral = [](const std::string&) {};
  WebRtcService service({{.name = "rover-cam0", .frames = &frames}}, settings);

  testThread = g_thread_self();
  guint added = g_signal_lookup("deep-element-added", GST_TYPE_BIN);
  gulong hook = g_signal_add_emission_hook(added, 0, holdWebrtcbinsOperation, nullptr, nullptr);
  GMainLoop* loop = g_main_loop_new(nullptr, FALSE);
  std::optional<Expected<WebRtcService::Answer, WebRtcService::Refusal>> answer;
  service.offer("rover-cam0", offerWith(""), "127.0.0.1", [&](auto given) {
    answer = std::move(given);
    g_main_loop_quit(loop);
  });
  // The longest the main loop went without turning, seen by a timer of
  // 20 ms (the service's own sweep, twice a second, runs among them).
  struct Turns {
    Clock::time_point last = Clock::now();
    Clock::duration longest{};
  } turns;
  guint ticker = g_timeout_add(
      20,
      [](gpointer data) -> gboolean {
        auto* seen = static_cast<Turns*>(data);
        auto now = Clock::now();
        seen->longest = std::max(seen->longest, now - seen->last);
        seen->last = now;
        return G_SOURCE_CONTINUE;
      },
      &turns);
  guint limit = g_timeout_add(
      patience(15000ms).count(),
      [](gpointer running) -> gboolean {
        g_main_loop_quit(static_cast<GMainLoop*>(running));
        return G_SOURCE_REMOVE;
      },
      loop);
  g_main_loop_run(loop);
  g_source_remove(ticker);
  if (answer) g_source_remove(limit);
  g_main_loop_unref(loop);
  g_signal_remove_emission_hook(added, hook);

  ASSERT_TRUE(answer) << "no answer in 15 s";
  ASSERT_TRUE(*answer) << answer->error().why;
  EXPECT_TRUE(held) << "webrtcbin added no element of its own: nothing was held";
  auto longest = std::chrono::duration_cast<std::chrono::milliseconds>(turns.longest);
  // Well under the hold: a loaded machine may delay a turn, never by the
  // whole of webrtcbin's operation.
  EXPECT_LT(longest, kHeld / 2) << "the main loop stood still for " << longest.count() << " ms";
  std::cerr << "[ measured ] longest main loop turn while a viewer was prepared: "
            << longest.count() << " ms\n";
}

}  // namespace
