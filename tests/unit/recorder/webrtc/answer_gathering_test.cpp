// When a WHEP answer leaves: after its candidates, with time passed in.
#include "webrtc/answer_gathering.h"

#include <gtest/gtest.h>

namespace wircam::recorder {
namespace {

using namespace std::chrono_literals;
using Clock = AnswerGathering::Clock;

const Clock::time_point kOffered{};

TEST(AnswerGathering, LeavesOnceGatheringIsCompleteWithoutWaitingOutItsPatience) {
  AnswerGathering gathering(3s);
  gathering.answerMade(kOffered + 100ms);
  gathering.candidateFound();
  EXPECT_FALSE(gathering.ready(kOffered + 200ms));
  gathering.gatheringComplete();
  EXPECT_TRUE(gathering.ready(kOffered + 200ms));
  EXPECT_EQ(gathering.progress(), "answer made, 1 candidate(s) of its own, gathering complete");
}

TEST(AnswerGathering, NeverLeavesBeforeTheAnswerIsMade) {
  AnswerGathering gathering(3s);
  gathering.candidateFound();
  gathering.gatheringComplete();
  EXPECT_FALSE(gathering.ready(kOffered + 10s));
  EXPECT_FALSE(gathering.patienceEnds());
  EXPECT_EQ(gathering.progress(), "webrtcbin made no answer yet");
}

TEST(AnswerGathering, ThePatienceStartsWithTheAnswerNotWithTheOffer) {
  // Beside eight suites and two busy loops the answer took seconds to make:
  // counted from the offer, the patience was over before the first
  // candidate and the answer left without any (seen in CI).
  AnswerGathering gathering(3s);
  gathering.answerMade(kOffered + 4s);
  EXPECT_EQ(gathering.patienceEnds(), kOffered + 7s);
  EXPECT_FALSE(gathering.ready(kOffered + 4s));
  gathering.candidateFound();
  EXPECT_FALSE(gathering.ready(kOffered + 6999ms));
  EXPECT_TRUE(gathering.ready(kOffered + 7s));
  EXPECT_EQ(gathering.candidates(), 1);
}

TEST(AnswerGathering, AtItsPatiencesEndItGoesWithWhatItHasEvenNothing) {
  // Better than a refusal: ICE still connects wherever the recorder
  // reaches the viewer's own candidates.
  AnswerGathering gathering(3s);
  gathering.answerMade(kOffered);
  EXPECT_TRUE(gathering.ready(kOffered + 3s));
  EXPECT_EQ(gathering.candidates(), 0);
  EXPECT_EQ(gathering.progress(), "answer made, 0 candidate(s) of its own, gathering on");
}

}  // namespace
}  // namespace wircam::recorder
