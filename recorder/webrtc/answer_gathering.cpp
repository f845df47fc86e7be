#include "webrtc/answer_gathering.h"

namespace wircam::recorder {

std::string AnswerGathering::progress() const {
  if (!answerMadeAt_) return "webrtcbin made no answer yet";
  return "answer made, " + std::to_string(candidates_) + " candidate(s) of its own, gathering " +
         (complete_ ? "complete" : "on");
}

}  // namespace wircam::recorder
