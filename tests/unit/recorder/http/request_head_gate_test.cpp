#include "http/request_head_gate.h"

#include <gtest/gtest.h>

#include <string>

namespace {

using wircam::recorder::HeadVerdict;
using wircam::recorder::judgeHead;
using wircam::recorder::kHeadLimit;

TEST(RequestHeadGate, AWholeHeadWithinTheBoundGoesOn) {
  EXPECT_EQ(judgeHead("GET / HTTP/1.1\r\nHost: x\r\n\r\n"), HeadVerdict::Whole);
  // Its body, or the next request, may follow in the same bytes.
  std::string head = "POST /w HTTP/1.1\r\nContent-Length: 70000\r\n\r\n";
  EXPECT_EQ(judgeHead(head + std::string(70000, 'b')), HeadVerdict::Whole);
  std::string exactly = "GET / HTTP/1.1\r\nX: " + std::string(kHeadLimit - 23, 'x') + "\r\n\r\n";
  ASSERT_EQ(exactly.size(), kHeadLimit);
  EXPECT_EQ(judgeHead(exactly), HeadVerdict::Whole);
}

TEST(RequestHeadGate, AnUnfinishedHeadWithinTheBoundIsWaitedFor) {
  EXPECT_EQ(judgeHead(""), HeadVerdict::Unfinished);
  EXPECT_EQ(judgeHead("GET / HTTP/1.1\r\nHost: x\r\n"), HeadVerdict::Unfinished);
  EXPECT_EQ(judgeHead("GET /" + std::string(kHeadLimit - 5, 'q')), HeadVerdict::Unfinished);
}

TEST(RequestHeadGate, PastTheBoundTheLongRequestLineIs414AndLongFieldsAre431) {
  EXPECT_EQ(judgeHead("GET /?q=" + std::string(kHeadLimit, 'q')), HeadVerdict::UriTooLong);
  EXPECT_EQ(judgeHead("GET / HTTP/1.1\r\nX: " + std::string(kHeadLimit, 'x')),
            HeadVerdict::FieldsTooLarge);
  // Whole, but one byte past the bound: libsoup would drop it.
  std::string over = "GET / HTTP/1.1\r\nX: " + std::string(kHeadLimit - 22, 'x') + "\r\n\r\n";
  ASSERT_EQ(over.size(), kHeadLimit + 1);
  EXPECT_EQ(judgeHead(over), HeadVerdict::FieldsTooLarge);
}

}  // namespace
