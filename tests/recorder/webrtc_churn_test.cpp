// 20 WebRTC viewers (one Chromium, twenty peer connections) connecting and
// leaving again and again for a minute: every round connects, every viewer
// is let go, and the recorder's threads, file descriptors and memory come
// back to where they were after the first round. A soak (CTest label
// "soak"). It found webrtcbins kept alive by their pipeline's messages
// (2 threads and 16 descriptors a viewer, for ever).
#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>

#include "devtools_page.h"
#include "headless_chromium.h"
#include "process_memory.h"
#include "recorder_process.h"
#include "signed_in_page.h"
#include "wait_for.h"

namespace {

using namespace wircam;
using namespace wircam::testing;
using std::chrono::milliseconds;
using Clock = std::chrono::steady_clock;

// One round in the page: `viewers` peer connections offered over WHEP at
// once; how many connected, then all closed and their sessions deleted.
std::string roundScript(const std::string& camera, int viewers) {
  return "(async () => { const one = async () => { const pc = new RTCPeerConnection(); "
         "pc.addTransceiver('video', {direction: 'recvonly'}); "
         "await pc.setLocalDescription(await pc.createOffer()); "
         "await new Promise(d => { const t = setTimeout(d, 2000); pc.onicegatheringstatechange = "
         "() => { if (pc.iceGatheringState === 'complete') { clearTimeout(t); d(); } }; }); "
         "const r = await fetch('/api/cameras/" +
         camera +
         "/whep', {method: 'POST', headers: {'Content-Type': 'application/sdp'}, body: "
         "pc.localDescription.sdp}); if (r.status !== 201) { pc.close(); return [false, null]; } "
         "const where = r.headers.get('Location'); "
         "await pc.setRemoteDescription({type: 'answer', sdp: await r.text()}); "
         "const up = await new Promise(d => { const t = setTimeout(() => d(false), 5000); "
         "const check = () => { if (pc.connectionState === 'connected') { clearTimeout(t); "
         "d(true); } }; pc.onconnectionstatechange = check; check(); }); return [up, pc, where]; "
         "}; const all = await Promise.all(Array.from({length: " +
         std::to_string(viewers) +
         "}, one)); for (const [, pc, where] of all) { if (pc) pc.close(); if (where) await "
         "fetch(where, {method: 'DELETE'}); } return all.filter(([up]) => up).length; })()";
}

TEST(WebRtcChurn, TwentyViewersComingAndGoingForAMinuteLeaveNothingBehind) {
  if (!chromiumInstalled()) GTEST_SKIP() << "chromium is not installed";
  FollowedCar car;
  ASSERT_TRUE(car.device);
  SignedInPage signedIn(car.device->port(), {}, "webrtc-churn");
  ASSERT_TRUE(signedIn.page);
  auto& page = *signedIn.page;
  // The sign-in page: same origin and cookie, no live view of its own.
  ASSERT_TRUE(page.navigate(signedIn.url + "login"));
  std::string camera = "127.0.0.1-" + std::to_string(car.device->port()) + "-cam0";
  ASSERT_TRUE(signedIn.recorder.waitForText(camera + ": live", milliseconds(10000)));
  constexpr int kViewers = 20;
  auto allGone = [&] {
    return waitFor([&] {
      return signedIn.recorder.log().rfind(", 0 now") > signedIn.recorder.log().rfind(", 1 now");
    });
  };
  int rounds = 0;
  long afterFirst = 0;
  std::string residentByRound;  // "MB@round", every tenth round
  ProcessCounts first;
  // WIRCAM_SOAK_SECONDS makes it longer, to see where the memory goes (the
  // recorder's --duration allows 15 minutes).
  const char* seconds = std::getenv("WIRCAM_SOAK_SECONDS");
  auto length = std::chrono::seconds(seconds ? std::atoi(seconds) : 60);
  for (auto end = Clock::now() + length; Clock::now() < end; ++rounds) {
    // Chromium counts closed peer connections until they are collected
    // (500 a renderer at most).
    page.call("HeapProfiler.collectGarbage");
    // (A round takes a few seconds; more on a loaded machine.)
    auto round = page.call("Runtime.evaluate",
                           {{"expression", roundScript(camera, kViewers)},
                            {"returnByValue", true},
                            {"awaitPromise", true}},
                           milliseconds(30000));
    ASSERT_EQ(round["result"].value("value", nlohmann::json()), kViewers)
        << "round " << rounds << ": " << round.dump() << "\n"
        << signedIn.recorder.log();
    ASSERT_TRUE(allGone()) << signedIn.recorder.log();
    if (rounds == 0) {
      afterFirst = residentKb(signedIn.recorder.pid());
      first = processCounts(signedIn.recorder.pid());
    }
    if (rounds % 10 == 0)
      residentByRound += " " + std::to_string(residentKb(signedIn.recorder.pid()) / 1024) + "@" +
                         std::to_string(rounds);
  }
  // Not a leak, the allocator's high-water mark: glibc keeps each of its
  // arenas (16 on two cores) at the most it ever held for reuse. Measured
  // over 225 rounds (4,500 viewers): 47 MB after the first, up to 75 MB by
  // round 75, then down and level at 65-67 MB to the end, while the heap
  // in use (malloc_info) stayed at 7-19 MB throughout; a minute in CI
  // grew 17 MB. A leaked viewer (its webrtcbin, threads and buffers, about
  // 512 KB) would pass the bound within four rounds; smaller leaks are
  // LeakSanitizer's to find (WIRCAM_SANITIZE=address).
  const long boundKb = 40L * 1024;
  long atEnd = 0;
  waitFor([&] {
    atEnd = residentKb(signedIn.recorder.pid());
    return atEnd - afterFirst < boundKb;
  });
  // Every viewer's threads and sockets went with it (a leak would be 2 and
  // 16 a viewer, and stays); the browser keeps up to 6 HTTP connections
  // open or not. A viewer's streaming threads go back to GStreamer's task
  // pool when it leaves and end after half a second idle there: a fresh
  // root in CI counted the last round's still waiting (89 against 86).
  ProcessCounts last;
  waitFor(
      [&] {
        last = processCounts(signedIn.recorder.pid());
        return last.threads <= first.threads && last.descriptors <= first.descriptors + 6;
      },
      milliseconds(10000));
  EXPECT_LE(last.threads, first.threads);
  EXPECT_LE(last.descriptors, first.descriptors + 6);
  std::cerr << "[ measured ] " << rounds << " rounds of " << kViewers
            << " WebRTC viewers: recorder " << afterFirst / 1024 << " MB, " << first.threads
            << " threads, " << first.descriptors << " descriptors after the first; " << atEnd / 1024
            << " MB, " << last.threads << ", " << last.descriptors
            << " after the last; MB by round:" << residentByRound << "\n";
  EXPECT_GE(rounds, 5);
  // No viewer asks the router for a UPnP port mapping (libnice's default):
  // twenty at once fought over ports, each warning in the log.
  EXPECT_EQ(signedIn.recorder.log().find("gupnp"), std::string::npos) << signedIn.recorder.log();
  // (Not under ASan: its quarantine keeps what is freed, so resident memory
  // says nothing of leaks there; LeakSanitizer checks them instead.)
  if (!kAddressSanitizer) {
    EXPECT_LT(atEnd - afterFirst, boundKb) << "grew " << (atEnd - afterFirst) / 1024 << " MB";
  }
}

}  // namespace
