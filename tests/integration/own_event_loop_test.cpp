// Every vehicle link runs on the event loop it is given, so a test (or an
// application) can own one: the link's events come from that loop's
// thread, the link is shared only by the users of that loop, and once the
// links are let go the loop can end. Over real loopback sockets, against
// the simulated device, receiver, robot and dashboard.
#include <gtest/gtest.h>

#include <atomic>
#include <memory>

#include "btemp/btemp_controller.h"
#include "devices/btemp/btemp_robot.h"
#include "devices/rcoip/rcoip_receiver.h"
#include "devices/wirc/device.h"
#include "link/event_loop.h"
#include "marvelmind/position_client.h"
#include "marvelmind_dashboard.h"
#include "rcoip/rcoip_transmitter.h"
#include "wait_for.h"
#include "wirc/transmitter_session.h"

namespace wircam {
namespace {

using testing::waitFor;

// Counts a link's events, and those that came from another thread than
// the loop's.
struct ThreadCheck {
  explicit ThreadCheck(link::EventLoop& l) : loop(l) {}
  link::EventLoop& loop;
  std::atomic<int> events{0}, elsewhere{0};
  void saw() {
    ++events;
    if (!loop.inLoopThread()) ++elsewhere;
  }
};

// Acquires `open(loop, user)` twice on an own loop and once on the shared
// one; checks where the events come from and who shares the link.
template <typename Open>
void runsOnItsOwnLoop(Open open) {
  auto loop = std::make_unique<link::EventLoop>();
  ThreadCheck check(*loop);
  {
    auto first = open(*loop, "first");
    auto second = open(*loop, "second");
    auto elsewhere = open(link::EventLoop::shared(), "elsewhere");
    ASSERT_TRUE(first && second && elsewhere);
    EXPECT_EQ(first->get(), second->get()) << "one loop, one link per vehicle";
    EXPECT_NE(first->get(), elsewhere->get()) << "another loop, another link";
    // Gone again: a vehicle answers one controller (an RCOIP receiver the
    // sender its reply interval falls to, a BTEMP robot the one registered).
    elsewhere->reset();
    // Added on the loop: a new listener hears the link's last state at
    // once, from the thread that adds it.
    int id = 0;
    loop->invoke([&] { id = (*first)->addListener([&](const link::LinkEvent&) { check.saw(); }); });
    ASSERT_TRUE(waitFor([&] { return (*first)->status().state == link::LinkState::Live; }));
    ASSERT_TRUE(waitFor([&] { return check.events > 0; }));
    EXPECT_EQ(check.elsewhere, 0);
    (*first)->removeListener(id);
  }
  loop.reset();  // its thread ends: nothing of the links is left on it
}

// The same for the link `Link::acquire` opens with a `Config` naming the
// simulated `peer` on loopback.
template <typename Link, typename Config, typename Peer>
void runsOnItsOwnLoopTo(const Peer& peer) {
  Config config{.host = "127.0.0.1", .port = peer.port()};
  runsOnItsOwnLoop([&](link::EventLoop& loop, const std::string& user) {
    return Link::acquire(config, user, loop);
  });
}

TEST(OwnEventLoop, AWircSessionRunsOnTheLoopItIsGiven) {
  auto device = wirc::Device::start({.port = 0}, nullptr);
  ASSERT_TRUE(device) << device.error();
  runsOnItsOwnLoopTo<wirc::TransmitterSession, wirc::SessionConfig>(**device);
}

TEST(OwnEventLoop, AnRcoipLinkRunsOnTheLoopItIsGiven) {
  auto receiver = rcoip::Receiver::start({.port = 0});
  ASSERT_TRUE(receiver);
  runsOnItsOwnLoopTo<rcoip::Transmitter, rcoip::TransmitterConfig>(**receiver);
}

TEST(OwnEventLoop, ABtempLinkRunsOnTheLoopItIsGiven) {
  auto robot = btemp::Robot::start({.port = 0});
  ASSERT_TRUE(robot);
  runsOnItsOwnLoopTo<btemp::Controller, btemp::ControllerConfig>(**robot);
}

TEST(OwnEventLoop, AMarvelmindClientRunsOnTheLoopItIsGiven) {
  auto dashboard =
      sim::MarvelmindDashboard::start({.beacons = {5}, .rate = 32, .noise = 0}, [](size_t) {
        return std::array<double, 3>{1, 2, 0};
      });
  ASSERT_TRUE(dashboard) << dashboard.error();
  auto loop = std::make_unique<link::EventLoop>();
  ThreadCheck check(*loop);
  auto client = marvelmind::PositionClient::start(
      {.port = (*dashboard)->port(), .beacons = {5}, .pollRate = 20},
      [&](const marvelmind::PositionEvent&) { check.saw(); }, *loop);
  ASSERT_TRUE(client) << client.error();
  ASSERT_TRUE(waitFor([&] { return check.events >= 3; }));
  EXPECT_EQ(check.elsewhere, 0);
  client->reset();  // the listener never runs again
  loop.reset();
}

}  // namespace
}  // namespace wircam
