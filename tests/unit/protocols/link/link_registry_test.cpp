// How the links of WiRC, RCOIP and BTEMP are shared: one per vehicle and
// event loop, under the one settings policy, for links whose settings are
// fixed once open and for links that take over new ones.
#include "link/link_registry.h"

#include <gtest/gtest.h>

#include "link/event_loop.h"

namespace {

using namespace wircam;
using namespace wircam::link;

// A link whose settings are plain values (a WiRC session's can change).
struct FakeLink {
  SettingValues settings;
};

Expected<std::shared_ptr<FakeLink>, std::string> openWith(SettingValues settings, int& opened) {
  ++opened;
  return std::make_shared<FakeLink>(FakeLink{std::move(settings)});
}

TEST(LinkRegistry, OneLinkPerVehicleAndLoopWhileAUserHoldsIt) {
  LinkRegistry<FakeLink> registry;
  EventLoop other;
  int opened = 0;
  auto open = [&] { return openWith({}, opened); };
  auto a = registry.acquire(EventLoop::shared(), "car", {}, "a", open);
  auto b = registry.acquire(EventLoop::shared(), "car", {}, "b", open);
  auto c = registry.acquire(other, "car", {}, "c", open);
  ASSERT_TRUE(a && b && c);
  EXPECT_EQ(a->get(), b->get());
  EXPECT_NE(a->get(), c->get());
  EXPECT_EQ(opened, 2);
  a->reset();
  b->reset();
  auto again = registry.acquire(EventLoop::shared(), "car", {}, "d", open);
  EXPECT_EQ(opened, 3);  // the last user let go: a new link
}

TEST(LinkRegistry, AFixedLinkRefusesOtherSettingsNamingBothUsers) {
  LinkRegistry<FakeLink> registry;
  int opened = 0;
  SettingValues four{{"channels", "4"}}, eight{{"channels", "8"}};
  auto first = registry.acquire(EventLoop::shared(), "car", four, "first",
                                [&] { return openWith(four, opened); });
  ASSERT_TRUE(first);
  auto second = registry.acquire(EventLoop::shared(), "car", eight, "second",
                                 [&] { return openWith(eight, opened); });
  ASSERT_FALSE(second);
  for (const char* part : {"channels=8 of second", "channels=4 of first", "car"})
    EXPECT_NE(second.error().find(part), std::string::npos) << second.error();
}

TEST(LinkRegistry, AChangeableLinkAdoptsWhatNobodyGaveAndRefusesWhatSomebodyDid) {
  LinkRegistry<FakeLink> registry;
  int opened = 0;
  auto current = [](FakeLink& link) { return link.settings; };
  std::vector<std::string> adopted;
  auto adopt = [&](FakeLink& link, const std::vector<std::string>& names) {
    for (const auto& name : names) {
      link.settings[name] = "7";
      adopted.push_back(name);
    }
  };
  auto open = [&] { return openWith({{"priority", "0"}}, opened); };
  auto plain =
      registry.acquireChangeable(EventLoop::shared(), "car", {}, "plain", open, current, adopt);
  ASSERT_TRUE(plain);
  auto seven = registry.acquireChangeable(EventLoop::shared(), "car", {{"priority", "7"}}, "seven",
                                          open, current, adopt);
  ASSERT_TRUE(seven);
  EXPECT_EQ(adopted, std::vector<std::string>{"priority"});
  EXPECT_EQ((*plain)->settings["priority"], "7");
  auto three = registry.acquireChangeable(EventLoop::shared(), "car", {{"priority", "3"}}, "three",
                                          open, current, adopt);
  ASSERT_FALSE(three);
  EXPECT_NE(three.error().find("of seven"), std::string::npos) << three.error();
  // Once "seven" lets go, nobody holds the value: "three" may change it.
  seven->reset();
  EXPECT_TRUE(registry.acquireChangeable(EventLoop::shared(), "car", {{"priority", "3"}}, "three",
                                         open, current, adopt));
  EXPECT_EQ(opened, 1);
}

}  // namespace
