// When a WHEP answer may leave: with the recorder's ICE candidates, which
// webrtcbin finds one by one after the answer is made. Sans-IO: the viewer
// tells it what happened and when, and asks.
#pragma once

#include <chrono>
#include <optional>
#include <string>

namespace wircam::recorder {

class AnswerGathering {
 public:
  using Clock = std::chrono::steady_clock;

  // How long an answer waits for the candidates once it is made: host
  // candidates come at once, STUN's and TURN's after a round trip.
  explicit AnswerGathering(Clock::duration patience) : patience_(patience) {}

  void answerMade(Clock::time_point now) { answerMadeAt_ = now; }
  void candidateFound() { ++candidates_; }
  void gatheringComplete() { complete_ = true; }

  // Once gathering is complete, or `patience` after the answer was made,
  // with the candidates found by then: never before the answer. A loaded
  // machine can take seconds to make the answer, so the wait starts with
  // it, not with the offer (counted from the offer, it was over before the
  // first candidate, seen in CI). An answer without candidates of ours
  // still connects wherever the recorder reaches the viewer (ICE learns
  // the recorder's address from its checks); a refusal never does.
  bool ready(Clock::time_point now) const {
    return answerMadeAt_ && (complete_ || now - *answerMadeAt_ >= patience_);
  }
  int candidates() const { return candidates_; }

  // When `ready` may change by time alone: the patience's end, once the
  // answer is made.
  std::optional<Clock::time_point> patienceEnds() const {
    if (!answerMadeAt_) return std::nullopt;
    return *answerMadeAt_ + patience_;
  }

  // Where it is, for a log: "webrtcbin made no answer yet", "answer made,
  // 2 candidate(s) of its own, gathering on".
  std::string progress() const;

 private:
  Clock::duration patience_;
  std::optional<Clock::time_point> answerMadeAt_;
  int candidates_ = 0;
  bool complete_ = false;
};

}  // namespace wircam::recorder
