// The learning channel's names (graphs/channels/learning_channel.hpp).
#include "graphs/channels/learning_channel.hpp"

namespace orthoflow::graphs {

std::string_view to_string(LearningCommand::Kind kind) noexcept {
  switch (kind) {
    case LearningCommand::Kind::TEACH:
      return "teach";
    case LearningCommand::Kind::CORRECT:
      return "correct";
    case LearningCommand::Kind::FORGET:
      return "forget";
    case LearningCommand::Kind::ASK:
      return "ask";
    case LearningCommand::Kind::UNDO:
      return "undo";
  }
  return "unknown";
}

std::string_view to_string(LearningAck::Outcome outcome) noexcept {
  using O = LearningAck::Outcome;
  switch (outcome) {
    case O::STORED:
      return "stored";
    case O::LEARNED:
      return "learned";
    case O::ANSWERED:
      return "answered";
    case O::NO_SUCH_TRACK:
      return "no_such_track";
    case O::NOT_DESCRIBED:
      return "not_described";
    case O::BAD_LABEL:
      return "bad_label";
    case O::REJECTED:
      return "rejected";
    case O::UNKNOWN_LABEL:
      return "unknown_label";
    case O::WRITE_FAILED:
      return "write_failed";
    case O::BUSY:
      return "busy";
    case O::NOTHING_TO_UNDO:
      return "nothing_to_undo";
  }
  return "unknown";
}

}  // namespace orthoflow::graphs
