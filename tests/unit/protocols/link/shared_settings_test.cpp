// The one policy by which the users of a shared link agree on its settings.
#include "link/shared_settings.h"

#include <gtest/gtest.h>

namespace {

using namespace wircam::link;

const std::string kKey = "rcoip://127.0.0.1:9048";

TEST(SettingClaims, AValueAnotherUserGaveIsAConflictNamingBoth) {
  SettingClaims claims;
  SettingValues current{{"lost-timeout", "500ms"}, {"rate", "50"}};
  ASSERT_TRUE(claims.claim(kKey, "wirccontrol0", current, current, false));
  auto refused = claims.claim(kKey, "wirccontrol1", {{"lost-timeout", "300ms"}}, current, true);
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error(),
            "lost-timeout=300ms of wirccontrol1 conflicts with lost-timeout=500ms of "
            "wirccontrol0, which shares the link to rcoip://127.0.0.1:9048: give both the same "
            "value, or set it on one only");
  // The same value is no conflict.
  EXPECT_TRUE(claims.claim(kKey, "wirccontrol1", {{"lost-timeout", "500ms"}}, current, false));
}

TEST(SettingClaims, AValueNobodyGaveIsTakenOverWhereTheLinkCanChangeIt) {
  SettingClaims claims;
  SettingValues current{{"transmitter-name", "'wircam'"}, {"priority", "0"}};
  ASSERT_TRUE(claims.claim(kKey, "wirccontrol0", {}, current, true));  // gave nothing
  auto changes = claims.claim(kKey, "wircsrc0", {{"priority", "7"}}, current, true);
  ASSERT_TRUE(changes);
  EXPECT_EQ(*changes, std::vector<std::string>{"priority"});
  auto fixed = claims.claim(kKey, "wircsrc1", {{"transmitter-name", "'bob'"}}, current, false);
  ASSERT_FALSE(fixed);
  EXPECT_NE(fixed.error().find("cannot change while it is in use"), std::string::npos);
}

TEST(SettingClaims, LettingGoEndsAUsersClaims) {
  SettingClaims claims;
  SettingValues current{{"priority", "7"}};
  ASSERT_TRUE(claims.claim(kKey, "alice", current, current, true));
  ASSERT_TRUE(claims.claim(kKey, "carol", current, current, true));
  claims.release("alice");
  // carol still gives 7: a different value is still a conflict.
  EXPECT_FALSE(claims.claim(kKey, "bob", {{"priority", "3"}}, current, true));
  claims.release("carol");
  auto changes = claims.claim(kKey, "bob", {{"priority", "3"}}, current, true);
  ASSERT_TRUE(changes);
  EXPECT_EQ(changes->size(), 1u);
}

}  // namespace
