// What the recorder says when its cameras may need more open files than
// the process may open (at its start and at a reload that adds cameras).
#include "app/open_files_check.h"

#include <gtest/gtest.h>

namespace {

using wircam::recorder::openFilesShortfall;

TEST(OpenFilesCheck, CamerasThatFitSayNothing) {
  EXPECT_EQ(openFilesShortfall(8, 1024), std::nullopt);
  EXPECT_EQ(openFilesShortfall(60, 1024), std::nullopt);  // 60 × 16 + 64 = 1024
}

TEST(OpenFilesCheck, CamerasThatDoNotFitAreToldTheLimitToSet) {
  auto said = openFilesShortfall(61, 1024);
  ASSERT_TRUE(said);
  EXPECT_EQ(*said,
            "61 cameras may need 1040 open files, and this process may open 1024: raise the limit "
            "(`ulimit -n 1040` in its shell, LimitNOFILE=1040 in its systemd unit) or some "
            "cameras will not start");
}

}  // namespace
