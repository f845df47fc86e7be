// The Marvelmind position client against the simulated dashboard and
// against a raw socket that plays a hostile one, over real loopback UDP.
#include <gtest/gtest.h>

#include <cmath>
#include <mutex>
#include <thread>
#include <vector>

#include "common/socket.h"
#include "marvelmind/position_client.h"
#include "marvelmind_dashboard.h"
#include "wait_for.h"

namespace wircam {
namespace {

using namespace std::chrono_literals;
using testing::waitFor;
namespace mm = marvelmind;

// What a client reported, kept for the test thread.
struct Reported {
  std::mutex mutex;
  std::vector<mm::Position> positions;
  std::vector<mm::PositionStale> stale;

  mm::PositionClient::Listener listener() {
    return [this](const mm::PositionEvent& event) {
      std::lock_guard lock(mutex);
      if (auto* p = std::get_if<mm::PositionReceived>(&event)) positions.push_back(p->position);
      if (auto* s = std::get_if<mm::PositionStale>(&event)) stale.push_back(*s);
    };
  }
  size_t count() {
    std::lock_guard lock(mutex);
    return positions.size();
  }
  size_t staleCount() {
    std::lock_guard lock(mutex);
    return stale.size();
  }
};

std::unique_ptr<sim::MarvelmindDashboard> startDashboard(sim::DashboardConfig config,
                                                         std::array<double, 3> where) {
  auto dashboard =
      sim::MarvelmindDashboard::start(std::move(config), [where](size_t) { return where; });
  EXPECT_TRUE(dashboard) << (dashboard ? "" : dashboard.error());
  return dashboard ? std::move(*dashboard) : nullptr;
}

TEST(MarvelmindClient, PollsTheSimulatedDashboardInBothUnits) {
  for (auto resolution : {mm::Resolution::kCentimetres, mm::Resolution::kMillimetres}) {
    auto dashboard =
        startDashboard({.beacons = {5, 6}, .rate = 32, .noise = 0}, {1.234, -2.5, 0.31});
    ASSERT_TRUE(dashboard);
    Reported reported;
    auto client = mm::PositionClient::start(
        {.port = dashboard->port(), .beacons = {5, 6}, .pollRate = 20, .resolution = resolution},
        reported.listener());
    ASSERT_TRUE(client) << client.error();
    ASSERT_TRUE(waitFor([&] { return reported.count() >= 10; }));
    std::lock_guard lock(reported.mutex);
    double precision = resolution == mm::Resolution::kCentimetres ? 0.005 : 0.0005;
    bool sawSix = false;
    for (const auto& p : reported.positions) {
      EXPECT_NEAR(p.x, 1.234, precision);
      EXPECT_NEAR(p.y, -2.5, precision);
      EXPECT_NEAR(p.z, 0.31, precision);
      EXPECT_LE(p.measured, p.received);
      sawSix |= p.beacon == 6;
    }
    EXPECT_TRUE(sawSix);
    EXPECT_EQ((*client)->stats().rejectedTotal(), 0u);
  }
}

TEST(MarvelmindClient, TakesWhatAPushingDashboardSends) {
  Reported reported;
  auto client = mm::PositionClient::start({.port = 1,
                                           .beacons = {9},
                                           .mode = mm::Mode::kStream,
                                           .listenPort = 0,
                                           .timestampUnit = mm::TimestampUnit::kMilliseconds},
                                          reported.listener());
  ASSERT_TRUE(client) << client.error();
  auto dashboard = startDashboard({.beacons = {9},
                                   .rate = 40,
                                   .noise = 0,
                                   .timestampUnit = mm::TimestampUnit::kMilliseconds,
                                   .pushTo = SocketAddress::loopback((*client)->localPort()),
                                   .pushResolution = mm::Resolution::kMillimetres},
                                  {3.0, 4.0, 0.5});
  ASSERT_TRUE(dashboard);
  ASSERT_TRUE(waitFor([&] { return reported.count() >= 20; }))
      << dashboard->summary() << "; client: " << (*client)->stats().foreign << " foreign, "
      << (*client)->stats().rejectedTotal() << " rejected";
  EXPECT_EQ((*client)->stats().requests, 0u);  // it only listens
  std::lock_guard lock(reported.mutex);
  // 40 measurements a second, in ms: the timestamps step by 25 ms (or a
  // multiple, where a push was lost), read in the right unit.
  for (size_t i = 1; i < reported.positions.size(); ++i) {
    double steps = (reported.positions[i].timestamp - reported.positions[i - 1].timestamp) / 0.025;
    EXPECT_NEAR(steps, std::round(steps), 0.04) << i;
    EXPECT_GE(std::round(steps), 1) << i;
  }
  EXPECT_DOUBLE_EQ(reported.positions.back().x, 3.0);
}

// A dashboard played by the test: answers each request with decoys (bad
// CRC, wrong type, code, size, beacon, short, long) around one good reply,
// and has a stranger send good-looking replies too.
TEST(MarvelmindClient, NoDecoyGetsThrough) {
  auto socket = bindUdp(SocketAddress::loopback(0));
  auto stranger = bindUdp(SocketAddress::loopback(0));
  ASSERT_TRUE(socket && stranger);
  uint16_t port = localAddress(socket->get()).port();
  Reported reported;
  auto client = mm::PositionClient::start({.port = port, .beacons = {5}, .pollRate = 50},
                                          reported.listener());
  ASSERT_TRUE(client) << client.error();

  auto decoy = [](mm::Reply reply, size_t byte, uint8_t value) {
    auto bytes = mm::encode(reply);
    bytes[byte] = value;
    return bytes;
  };
  uint64_t sentDecoys = 0, sentGood = 0, sentForeign = 0;
  std::vector<uint8_t> buffer(64);
  SocketAddress client_ = SocketAddress::loopback((*client)->localPort());
  for (uint32_t round = 1; round <= 40; ++round) {
    // The client's next request. (Tests run in parallel: a port another
    // test's client had may still get that test's datagrams; they are not
    // requests to answer.)
    ssize_t got = 0;
    for (SocketAddress from; !(from == client_);) {
      sockaddr_in sender{};
      socklen_t length = sizeof sender;
      got = recvfrom(socket->get(), buffer.data(), buffer.size(), 0,
                     reinterpret_cast<sockaddr*>(&sender), &length);
      from = SocketAddress(sender);
    }
    ASSERT_EQ(got, 10) << "a request is 10 bytes";
    mm::Reply far{.beacon = 5, .timestamp = round * 10 + 1, .xMm = 99000, .yMm = 99000};
    std::vector<std::vector<uint8_t>> decoys;
    auto badCrc = mm::encode(far);
    badCrc.back() ^= 0xFF;
    decoys.push_back(badCrc);
    decoys.push_back(decoy(far, 1, 0x48));  // type
    decoys.push_back(decoy(far, 2, 0x02));  // code
    decoys.push_back(decoy(far, 4, 0x11));  // data size
    decoys.push_back(mm::encode(mm::Reply{.beacon = 6, .timestamp = round * 10 + 2, .xMm = 99000}));
    auto shortOne = mm::encode(far);
    shortOne.pop_back();
    decoys.push_back(shortOne);
    auto longOne = mm::encode(far);
    longOne.push_back(0);
    decoys.push_back(longOne);
    decoys.push_back(std::vector<uint8_t>(600, 0x47));  // over any reply's size
    for (const auto& bytes : decoys) sentDecoys += sendDatagram(socket->get(), client_, bytes);
    mm::Reply good{
        .beacon = 5, .timestamp = round * 10, .xMm = 10 * (100 + static_cast<int32_t>(round))};
    sentGood += sendDatagram(socket->get(), client_, mm::encode(good));
    sentForeign += sendDatagram(stranger->get(), client_, mm::encode(far));
  }
  ASSERT_TRUE(waitFor([&] { return reported.count() == sentGood; }));
  ASSERT_TRUE(waitFor([&] {
    auto s = (*client)->stats();
    // (More foreign ones may come from other tests running in parallel.)
    return s.rejectedTotal() == sentDecoys && s.foreign >= sentForeign;
  })) << "rejected "
      << (*client)->stats().rejectedTotal() << " of " << sentDecoys;
  auto stats = (*client)->stats();
  EXPECT_EQ(stats.rejected["bad CRC"], 40u);
  EXPECT_EQ(stats.rejected["wrong beacon"], 40u);
  EXPECT_EQ(stats.rejected["wrong length"], 40u * 2);
  EXPECT_EQ(stats.rejected["unknown code"], 40u * 2);  // one of them the 600 bytes of 0x47
  EXPECT_EQ(stats.rejected["wrong packet type"], 40u);
  EXPECT_EQ(stats.rejected["wrong data size"], 40u);
  std::lock_guard lock(reported.mutex);
  for (size_t i = 0; i < reported.positions.size(); ++i) {
    EXPECT_EQ(reported.positions[i].beacon, 5);
    EXPECT_DOUBLE_EQ(reported.positions[i].x, (100.0 + static_cast<double>(i) + 1) / 100);
  }
}

TEST(MarvelmindClient, ASilentDashboardMakesThePositionStaleAndItComesBack) {
  Reported reported;
  auto dashboard = startDashboard({.beacons = {5}, .noise = 0}, {1, 1, 1});
  ASSERT_TRUE(dashboard);
  uint16_t port = dashboard->port();
  auto client = mm::PositionClient::start(
      {.port = port, .beacons = {5}, .pollRate = 20, .staleAfter = 300ms}, reported.listener());
  ASSERT_TRUE(client) << client.error();
  ASSERT_TRUE(waitFor([&] { return reported.count() >= 3; }));
  auto stopped = std::chrono::steady_clock::now();
  dashboard.reset();
  ASSERT_TRUE(waitFor([&] { return reported.staleCount() == 1; }, 2s));
  EXPECT_LT(std::chrono::steady_clock::now() - stopped, 300ms + 150ms);
  {
    std::lock_guard lock(reported.mutex);
    EXPECT_NE(reported.stale[0].reason.find("no reply from the dashboard"), std::string::npos)
        << reported.stale[0].reason;
  }
  // The same port again: positions come back.
  size_t before = reported.count();
  dashboard = startDashboard({.port = port, .beacons = {5}, .noise = 0}, {1, 1, 1});
  ASSERT_TRUE(dashboard);
  EXPECT_TRUE(waitFor([&] { return reported.count() > before; }));
}

TEST(MarvelmindClient, ABeaconOutOfSightIsStaleWhileTheDashboardAnswers) {
  // A dashboard that answers every request with the same measurement: the
  // beacon is out of sight of the stationary ones.
  auto socket = bindUdp(SocketAddress::loopback(0));
  ASSERT_TRUE(socket);
  setNonBlocking(socket->get());
  Reported reported;
  auto client = mm::PositionClient::start({.port = localAddress(socket->get()).port(),
                                           .beacons = {5},
                                           .pollRate = 20,
                                           .staleAfter = 300ms},
                                          reported.listener());
  ASSERT_TRUE(client);
  auto same = mm::encode(mm::Reply{.beacon = 5, .timestamp = 640, .xMm = 2000});
  std::vector<uint8_t> buffer(64);
  auto end = std::chrono::steady_clock::now() + 1s;
  while (std::chrono::steady_clock::now() < end && reported.staleCount() == 0) {
    receiveDatagrams(socket->get(), buffer, 8, [&](auto, const SocketAddress& from) {
      sendDatagram(socket->get(), from, same);
    });
    std::this_thread::sleep_for(5ms);
  }
  ASSERT_EQ(reported.staleCount(), 1u);
  EXPECT_EQ(reported.count(), 1u);  // the first answer; the rest repeat it
  EXPECT_GE((*client)->stats().repeats, 3u);
  std::lock_guard lock(reported.mutex);
  EXPECT_NE(reported.stale[0].reason.find("no new position of beacon 5"), std::string::npos)
      << reported.stale[0].reason;
}

TEST(MarvelmindClient, RefusesBadConfigurations) {
  auto listener = [](const mm::PositionEvent&) {};
  EXPECT_FALSE(mm::PositionClient::start({.beacons = {}}, listener));
  EXPECT_FALSE(mm::PositionClient::start({.beacons = {5}, .pollRate = 0}, listener));
  EXPECT_FALSE(
      mm::PositionClient::start({.host = "no.such.host.invalid", .beacons = {5}}, listener));
  EXPECT_FALSE(mm::parseBeacons("0"));
  EXPECT_FALSE(mm::parseBeacons("255"));
  EXPECT_FALSE(mm::parseBeacons("5,x"));
  EXPECT_EQ(*mm::parseBeacons("5,6,5"), (std::vector<uint8_t>{5, 6}));
}

}  // namespace
}  // namespace wircam
