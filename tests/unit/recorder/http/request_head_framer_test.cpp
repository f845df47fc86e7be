// What the web server is given of a client's bytes: heads whole, bodies as
// they come, and a head over libsoup's bound replaced by the request whose
// answer is 414 or 431 (the head's rest dropped), however the bytes are cut.
#include "http/request_head_framer.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace {

using wircam::recorder::kHeadLimit;
using wircam::recorder::RequestHeadFramer;

const std::string kLine = "GET /.wircam/overlong-head?part=line HTTP/1.1\r\nHost: wircam\r\n\r\n";
const std::string kFields =
    "GET /.wircam/overlong-head?part=fields HTTP/1.1\r\nHost: wircam\r\n\r\n";

// `bytes` fed in pieces of `piece` bytes: what went on.
std::string framed(const std::string& bytes, size_t piece, RequestHeadFramer& framer) {
  std::string out;
  for (size_t at = 0; at < bytes.size(); at += piece) framer.feed(bytes.substr(at, piece), out);
  return out;
}

TEST(RequestHeadFramer, HeadsGoOnWholeAndBodiesAsTheyCome) {
  std::string first = "GET /a HTTP/1.1\r\nHost: x\r\n\r\n";
  std::string offer = "POST /whep HTTP/1.1\r\nContent-Length: 5\r\n\r\nv=0\r\n";
  std::string second = "GET /b HTTP/1.1\r\nHost: x\r\n\r\n";
  for (size_t piece : {1u, 3u, 7u, 4096u}) {
    RequestHeadFramer framer;
    EXPECT_EQ(framed(first + offer + second, piece, framer), first + offer + second) << piece;
  }
  // Nothing of a head before its blank line.
  RequestHeadFramer framer;
  std::string out;
  framer.feed("GET /a HTTP/1.1\r\nHost: x\r\n", out);
  EXPECT_EQ(out, "");
  framer.feed("\r\n", out);
  EXPECT_EQ(out, first);
  // A head the client leaves unfinished goes on at its end, as it is.
  framer.feed("GET /c HT", out);
  framer.end(out);
  EXPECT_EQ(out, first + "GET /c HT");
}

TEST(RequestHeadFramer, AHeadAtTheBoundGoesOnAndOnePastItIsAnsweredInstead) {
  std::string exactly = "GET / HTTP/1.1\r\nX: " + std::string(kHeadLimit - 23, 'x') + "\r\n\r\n";
  ASSERT_EQ(exactly.size(), kHeadLimit);
  RequestHeadFramer atBound;
  EXPECT_EQ(framed(exactly, 1000, atBound), exactly);
  std::string over = "GET / HTTP/1.1\r\nX: " + std::string(kHeadLimit - 22, 'x') + "\r\n\r\n";
  RequestHeadFramer pastBound;
  EXPECT_EQ(framed(over, 1000, pastBound), kFields);
}

TEST(RequestHeadFramer, ALongRequestLineIs414LongFieldsAre431AndTheNextRequestGoesOn) {
  std::string next = "GET /status HTTP/1.1\r\nHost: x\r\n\r\n";
  std::string query = "GET /?q=" + std::string(200 * 1024, 'q') + " HTTP/1.1\r\nHost: x\r\n\r\n";
  std::string header = "GET / HTTP/1.1\r\nX-Big: " + std::string(100 * 1024, 'h') + "\r\n\r\n";
  for (size_t piece : {1000u, 4096u, 16384u}) {
    RequestHeadFramer framer;
    EXPECT_EQ(framed(query + next + header + next, piece, framer), kLine + next + kFields + next)
        << piece;
  }
  // Its rest still coming: dropped, and said so.
  RequestHeadFramer framer;
  std::string out;
  framer.feed("GET /?q=" + std::string(kHeadLimit, 'q'), out);
  EXPECT_EQ(out, kLine);
  EXPECT_TRUE(framer.dropping());
  framer.feed(std::string(5000, 'q') + " HTTP/1.1\r\n\r", out);
  EXPECT_TRUE(framer.dropping());
  framer.feed("\n" + next, out);  // the blank line cut between two reads
  EXPECT_FALSE(framer.dropping());
  EXPECT_EQ(out, kLine + next);
}

TEST(RequestHeadFramer, AfterAChunkedBodyOrAWebSocketsUpgradeEverythingPasses) {
  std::string junk = std::string(kHeadLimit * 2, 'j');
  for (std::string head :
       {"POST /x HTTP/1.1\r\nTransfer-Encoding: chunked\r\n\r\n",
        "GET /drive HTTP/1.1\r\nConnection: Upgrade\r\nUpgrade: websocket\r\n\r\n"}) {
    RequestHeadFramer framer;
    EXPECT_EQ(framed(head + junk, 4096, framer), head + junk) << head;
  }
}

}  // namespace
