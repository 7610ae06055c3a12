#pragma once
/// @file
/// @brief The learning channel: how a person (a UI, a DDS bridge, a test, a second thread) teaches,
/// corrects, asks and makes the robot forget while the tabletop graph runs (thesis chapter 5:
/// teach, ask, correct). Each sender connects once and gets a LearningClient; its commands go into
/// one bounded queue the recognise node drains every frame, and every command is acknowledged back
/// to its sender with its outcome: stored durably (after the synced write), learned in memory,
/// answered, or the error.
///
/// Real time: the recognise node's side (poll, acknowledge) is lock-free apart from a spin lock
/// held for one record copy; senders take a mutex among themselves (they are not on the frame
/// path).
#include <array>
#include <cstdint>
#include <string>
#include <string_view>

#include "core/fixed_text.hpp"

namespace orthoflow::graphs {

/// @brief What a sender asks of the learning channel.
/// @brief A TEACH by position names the object whose centroid is nearest, if it is this near: a
/// person pointing at something the robot does not see must not teach its neighbour.
inline constexpr float TEACH_POSITION_MAX_M = 0.15F;

struct LearningCommand {
  enum class Kind : std::uint8_t {
    TEACH,    ///< store the object's key views (and current view) under label; by track or by
              ///< position
    CORRECT,  ///< the answer for track was wrong: store its current view under label
    FORGET,   ///< forget category label
    ASK,      ///< what is track? (the current smoothed answer)
    UNDO,     ///< take back the most recent teach or correct not undone yet (from any sender)
  };
  Kind kind = Kind::TEACH;
  std::uint32_t track_id = 0;  ///< TEACH (when not by_position), CORRECT, ASK
  bool by_position = false;    ///< TEACH: the object whose centroid is nearest to position (within
                               ///< TEACH_POSITION_MAX_M; none nearer: NO_SUCH_TRACK)
  std::array<float, 3> position{};  ///< sensor frame, metres
  core::Text
      label;  ///< TEACH, CORRECT, FORGET: fill with label.try_assign() (refuses what would be cut)
  std::uint32_t sender = 0;    ///< set by LearningClient::send
  std::uint64_t sequence = 0;  ///< set by LearningClient::send (1, 2, ... per client)
};

/// @brief "teach", "correct", "forget", "ask" or "undo".
[[nodiscard]] std::string_view to_string(LearningCommand::Kind kind) noexcept;

/// @brief The answer to one command.
struct LearningAck {
  enum class Outcome : std::uint8_t {
    STORED,         ///< written to the perceptual memory (synced) and learned
    LEARNED,        ///< learned by the in-memory learner (no store configured)
    ANSWERED,       ///< ASK: label / score / unknown hold the answer
    NO_SUCH_TRACK,  ///< no object with that track id (or none at all) in the frame that handled it
    NOT_DESCRIBED,  ///< the object has no descriptor in that frame (too few points, degenerate)
    BAD_LABEL,      ///< empty or too long label
    REJECTED,       ///< the learner refused the views (wrong length, not finite)
    UNKNOWN_LABEL,  ///< FORGET of a category that was never taught
    WRITE_FAILED,   ///< the synced write failed: nothing was stored
    BUSY,           ///< the durable writer is behind: nothing was stored, send again
    NOTHING_TO_UNDO,  ///< UNDO with no lesson left to take back (or the memory changed under it)
  };
  std::uint64_t sequence = 0;  ///< the command's
  std::uint32_t sender = 0;
  LearningCommand::Kind kind = LearningCommand::Kind::TEACH;
  Outcome outcome = Outcome::NO_SUCH_TRACK;
  std::uint32_t track_id =
      0;  ///< the object the command applied to (TEACH by position: the one chosen)
  std::uint32_t views = 0;  ///< TEACH / CORRECT: views stored; UNDO: views taken back
  core::Text label;  ///< TEACH / CORRECT / FORGET: the label; UNDO: the category the undone lesson
                     ///< was for; ASK: the answer (empty = Unknown)
  float score = 0.0F;   ///< ASK: the learner's score for the answer
  bool unknown = true;  ///< ASK
  core::Text nearest;   ///< ASK: the nearest category even when the answer is Unknown (score is its
                        ///< decision value: the L2 distance for plain nearest neighbour)
  core::Text runner_up;          ///< ASK: the second-nearest category (empty when fewer than two)
  float runner_up_score = 0.0F;  ///< ASK: its decision value, on the scale of score
  std::uint64_t frame_id = 0;    ///< the frame that handled it
  [[nodiscard]] bool ok() const noexcept {
    return outcome == Outcome::STORED || outcome == Outcome::LEARNED ||
           outcome == Outcome::ANSWERED;
  }
};

/// @brief "stored", "learned", "answered", "no_such_track", ...
[[nodiscard]] std::string_view to_string(LearningAck::Outcome outcome) noexcept;

}  // namespace orthoflow::graphs
