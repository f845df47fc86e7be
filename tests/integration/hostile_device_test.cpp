// The WiRC link against devices that are broken, hostile or gone, played by
// a scripted fake device on loopback: memory stays flat, losses are noticed,
// every refusal is named, and a misbehaving device is dropped and retried.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/socket.h>

#include <array>
#include <mutex>
#include <thread>

#include "misbehaving_peers.h"
#include "process_memory.h"
#include "wait_for.h"
#include "wirc/transmitter_session.h"

namespace wircam::wirc {
namespace {

using std::chrono::milliseconds;
using testing::bytesOf;
using testing::PeerScript;
using testing::residentKb;
using testing::ScriptedPeer;
using testing::waitFor;
using Clock = std::chrono::steady_clock;

std::vector<uint8_t> repeated(const std::vector<uint8_t>& unit, size_t times) {
  std::vector<uint8_t> bytes;
  for (size_t i = 0; i < times; ++i) bytes.insert(bytes.end(), unit.begin(), unit.end());
  return bytes;
}

// Every event of one kind a link emits, for assertions.
template <typename T>
class Collected {
 public:
  explicit Collected(TransmitterSession& session) : session_(session) {
    id_ = session.addListener([this](const link::LinkEvent& event) {
      if (const auto* found = std::get_if<T>(&event)) {
        std::lock_guard lock(mutex_);
        events_.push_back(*found);
      }
    });
  }
  ~Collected() { session_.removeListener(id_); }
  std::vector<T> events() {
    std::lock_guard lock(mutex_);
    return events_;
  }

 private:
  TransmitterSession& session_;
  int id_;
  std::mutex mutex_;
  std::vector<T> events_;
};

std::shared_ptr<TransmitterSession> linkTo(const ScriptedPeer& peer, SessionConfig config = {}) {
  config.host = "127.0.0.1";
  config.port = peer.port();
  auto session = TransmitterSession::acquire(config);
  EXPECT_TRUE(session.has_value()) << session.error();
  return *session;
}

void expectDroppedAsMisbehavingWithFlatMemory(std::vector<uint8_t> flood) {
  ScriptedPeer peer({.chunks = {}, .flood = std::move(flood)});
  auto session = linkTo(peer);
  Collected<link::InputRejected> summaries(*session);
  long before = residentKb();
  auto start = Clock::now();
  // Dropped and tried again, more than once: the peer sees the new logins.
  EXPECT_TRUE(waitFor([&] { return peer.connections() >= 3; }, milliseconds(10000)));
  EXPECT_LT(residentKb() - before, 20 * 1024) << "memory grew with the garbage";
  EXPECT_NE(session->status().reason.find("dropped as misbehaving"), std::string::npos)
      << session->status().reason;
  EXPECT_GT(session->status().inputRejected, 100u);
  // The first summary may have left before the listener was added (it is
  // not sticky); the next comes a second later, from the next connection.
  EXPECT_TRUE(waitFor([&] { return !summaries.events().empty(); }, milliseconds(3000)));
  auto seconds = std::chrono::duration<double>(Clock::now() - start).count();
  // Summed up, not one event per bad byte: at most one summary a second.
  EXPECT_LE(summaries.events().size(), static_cast<size_t>(seconds) + 1);
}

TEST(HostileDevice, GarbageOnTheControlConnectionIsCountedAndTheDeviceDropped) {
  expectDroppedAsMisbehavingWithFlatMemory(repeated({0xAA, 0xBB}, 4096));
}

TEST(HostileDevice, AFloodOfUnknownCommandsIsCountedAndTheDeviceDropped) {
  auto unknown = frameRaw(0x77, std::vector<uint8_t>(16, 0x55));
  expectDroppedAsMisbehavingWithFlatMemory(repeated(unknown, 256));
}

TEST(HostileDevice, TheBackoffGrowsAcrossLoginsFollowedEachByGarbage) {
  // The login succeeds every time; what comes after it gets the device
  // dropped. A login is no success until the link has stayed up a while.
  ScriptedPeer peer;
  peer.play({.chunks = {peer.wst()}, .flood = repeated({0xAA, 0xBB}, 4096)});
  auto session = linkTo(peer, {.maxBadMessages = 10});
  Collected<link::StateChanged> states(*session);
  std::vector<int> waits;
  ASSERT_TRUE(waitFor(
      [&] {
        waits.clear();
        for (const auto& state : states.events())
          if (auto at = state.reason.find("retrying in "); at != std::string::npos)
            waits.push_back(std::stoi(state.reason.substr(at + 12)));
        return waits.size() >= 4;
      },
      milliseconds(10000)))
      << session->status().reason;
  EXPECT_GE(peer.connections(), 4);
  for (size_t i = 1; i < waits.size(); ++i)
    EXPECT_EQ(waits[i], std::min(2 * waits[i - 1], 5000)) << "after login " << i;
}

TEST(HostileDevice, ADeviceThatFallsSilentIsLostAfterTheLinkTimeout) {
  ScriptedPeer peer;
  peer.play({.chunks = {peer.wst()}, .statusReports = 1});
  auto session = linkTo(peer, {.linkTimeout = milliseconds(1000)});
  ASSERT_EQ(session->waitLoggedIn(milliseconds(3000)), std::nullopt);
  auto live = Clock::now();
  ASSERT_TRUE(waitFor([&] { return session->status().state == link::LinkState::Lost; }));
  EXPECT_GE(Clock::now() - live, milliseconds(900));  // not before the timeout
  EXPECT_NE(session->status().reason.find("no status report"), std::string::npos)
      << session->status().reason;
  // And it tries again.
  EXPECT_TRUE(waitFor([&] { return peer.connections() >= 2; }));
}

TEST(HostileDevice, ARefusedLoginIsReportedAtOnceWithItsMeaning) {
  ScriptedPeer peer({.chunks = {bytesOf(Err{static_cast<uint8_t>(Command::Tl),
                                            static_cast<uint16_t>(ErrorCode::Unauthorised)})}});
  auto start = Clock::now();
  auto session = linkTo(peer, {.loginTimeout = milliseconds(3000), .reconnect = false});
  auto error = session->waitLoggedIn(milliseconds(5000));
  ASSERT_TRUE(error.has_value());
  EXPECT_NE(error->find("unauthorised"), std::string::npos) << *error;
  EXPECT_LT(Clock::now() - start, milliseconds(2000)) << "waited for the login timeout";
}

TEST(HostileDevice, AControlRightSplitAcrossTheLoginReadIsNotLost) {
  ScriptedPeer peer;
  auto agr =
      bytesOf(Agr{.connectionId = 1, .name = "me", .notification = AccessNotification::Granted});
  auto first = peer.wst();
  first.insert(first.end(), agr.begin(), agr.begin() + 10);
  peer.play({.chunks = {first, {agr.begin() + 10, agr.end()}}});
  auto session = linkTo(peer);
  ASSERT_EQ(session->waitLoggedIn(milliseconds(3000)), std::nullopt);
  EXPECT_TRUE(waitFor([&] { return session->status().hasControl; }, milliseconds(2000)));
}

// An AGR naming another transmitter with these raw name bytes.
std::vector<uint8_t> revokedBy(const std::string& rawName) {
  std::vector<uint8_t> body(1 + 1 + 64 + 1, 0);  // ID, priority, name, notification
  body[0] = 2;
  std::copy(rawName.begin(), rawName.end(), body.begin() + 2);
  body.back() = static_cast<uint8_t>(AccessNotification::Revoked);
  return frameRaw(static_cast<uint8_t>(Command::Agr), body);
}

int datagramsWaiting(int fd) {
  int count = 0;
  std::array<uint8_t, 64> buffer;
  while (::recv(fd, buffer.data(), buffer.size(), MSG_DONTWAIT) > 0) ++count;
  return count;
}

TEST(HostileDevice, ARevokeNamingAPhoneStopsThePcd) {
  ScriptedPeer peer;
  auto granted =
      bytesOf(Agr{.connectionId = 1, .name = "me", .notification = AccessNotification::Granted});
  // The phone's default name, in UTF-8, with a typographic apostrophe.
  peer.play({.chunks = {peer.wst(), granted, revokedBy("P\xC3\xA1l\xE2\x80\x99s iPhone")}});
  auto session = linkTo(peer, {.keepalive = milliseconds(25)});
  Collected<link::ControlRightChanged> changes(*session);
  ASSERT_EQ(session->waitLoggedIn(milliseconds(3000)), std::nullopt);
  ASSERT_TRUE(waitFor([&] { return changes.events().size() == 2; }));
  EXPECT_TRUE(changes.events()[0].hasControl);
  EXPECT_FALSE(changes.events()[1].hasControl);
  EXPECT_EQ(changes.events()[1].holder, "Pál’s iPhone");
  EXPECT_GT(datagramsWaiting(peer.controlSocket()), 0);  // PCD while it had the right
  // Three keepalive periods without the right: not one PCD.
  std::this_thread::sleep_for(milliseconds(3 * 25));
  EXPECT_EQ(datagramsWaiting(peer.controlSocket()), 0);
}

}  // namespace
}  // namespace wircam::wirc
