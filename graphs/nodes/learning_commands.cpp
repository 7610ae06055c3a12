#include "graphs/nodes/learning_commands.hpp"

#include <cmath>

namespace orthoflow::graphs {

namespace {
using Kind = LearningCommand::Kind;
using Outcome = LearningAck::Outcome;
}  // namespace

LessonDesk::LessonDesk(LearningService& service, TrackMemories& memories)
    : service_(service),
      memories_(memories),
      lesson_(MAX_TEACH_VIEWS * service.descriptor_length()) {}

// The object a command names: by track id (its main piece, not a fragment, when both are in the
// frame), or the one whose centroid is nearest to the position, within TEACH_POSITION_MAX_M. -1
// when there is none.
std::int64_t LessonDesk::find_object(const FrameState& s, const LearningCommand& c) const noexcept {
  std::int64_t best = -1;
  float best_d = 1e30F;
  for (std::uint32_t k = 0; k < s.object_count; ++k) {
    const ObjectRecord& o = s.objects[k];
    if (!(c.kind == Kind::TEACH && c.by_position)) {
      if (o.track_id == c.track_id && c.track_id != 0 && (best < 0 || !o.fragment)) best = k;
      continue;
    }
    const float dx = o.stats.centroid[0] - c.position[0], dy = o.stats.centroid[1] - c.position[1],
                dz = o.stats.centroid[2] - c.position[2];
    const float d = std::sqrt(dx * dx + dy * dy + dz * dz);
    if (d < best_d && d <= TEACH_POSITION_MAX_M) {
      best_d = d;
      best = k;
    }
  }
  return best;
}

// A lesson needs the object's descriptor of this frame; without one the sender is told
// NOT_DESCRIBED.
bool LessonDesk::described(const ObjectRecord& o, LearningAck& ack) noexcept {
  if (o.described && o.descriptor_length == service_.descriptor_length()) return true;
  ack.outcome = Outcome::NOT_DESCRIBED;
  if (ack.sequence != 0) service_.acknowledge(ack);
  return false;
}

LearningAck LessonDesk::teach_object(const FrameBlock& block, std::uint32_t k,
                                     std::string_view label, LearningAck ack,
                                     std::int64_t stamp) noexcept {
  ObjectRecord& o = block.state().objects[k];
  ack.track_id = o.track_id;
  if (!described(o, ack)) return ack;
  const auto current = block.descriptor(k).first(o.descriptor_length);
  std::size_t views = 1;
  TrackMemory* t = o.track_id == 0 ? nullptr : memories_.find(o.track_id);
  const std::uint32_t untaught = t != nullptr ? t->untaught : 0;
  if (t != nullptr) {
    views = memories_.lesson(*t, current, o.key_view, lesson_);
  } else {
    std::copy(current.begin(), current.end(), lesson_.begin());
  }
  const auto lesson = std::span<const float>(lesson_).first(views * o.descriptor_length);
  ack = service_.teach(label, lesson, o.track_id, stamp, ack);
  if (t != nullptr && !ack.ok())
    t->untaught = untaught;  // refused: the key views wait for the next teach
  o.taught = ack.ok();
  if (o.taught) o.taught_as.assign(label);
  return ack;
}

void LessonDesk::answer(const FrameBlock& block, std::int64_t k, LearningAck ack) noexcept {
  const ObjectRecord& o = block.state().objects[static_cast<std::size_t>(k)];
  ack.track_id = o.track_id;
  ack.outcome = o.recognised ? Outcome::ANSWERED : Outcome::NOT_DESCRIBED;
  ack.label = o.label;
  ack.unknown = o.unknown;
  ack.score = o.score;
  ack.nearest = o.nearest;
  ack.runner_up = o.runner_up;
  ack.runner_up_score = o.runner_up_score;
  service_.acknowledge(ack);
}

// Thesis "correct": the answer was wrong; the current view is stored under the right label and the
// track's recorded answers are dropped, so the next frames show what the learner now says.
void LessonDesk::correct(const FrameBlock& block, std::int64_t k, std::string_view label,
                         LearningAck ack) noexcept {
  ObjectRecord& o = block.state().objects[static_cast<std::size_t>(k)];
  ack.track_id = o.track_id;
  if (!described(o, ack)) return;
  const auto stamp = static_cast<std::int64_t>(ack.frame_id);
  ack = service_.teach(label,
                       block.descriptor(static_cast<std::size_t>(k)).first(o.descriptor_length),
                       o.track_id, stamp, ack);
  o.taught = ack.ok();
  if (o.taught) o.taught_as.assign(label);
  if (TrackMemory* t = memories_.find(o.track_id); t != nullptr && ack.ok())
    TrackMemories::reset_votes(*t);
}

void LessonDesk::apply(const FrameBlock& block, const LearningCommand& c,
                       std::uint64_t frame_id) noexcept {
  LearningAck ack;
  ack.sequence = c.sequence;
  ack.sender = c.sender;
  ack.kind = c.kind;
  ack.frame_id = frame_id;
  ack.track_id = c.track_id;
  ack.label = c.label;
  if (c.kind == Kind::FORGET) {
    ack = service_.forget(c.label.view(), ack);
    if (ack.ok()) memories_.drop_answers(c.label.view());
    return;
  }
  if (c.kind == Kind::UNDO) {
    ack = service_.undo(ack);  // the tracks' answers of that category are asked again
    if (ack.ok()) memories_.drop_answers(ack.label.view());
    return;
  }
  const std::int64_t k = find_object(block.state(), c);
  if (k < 0) {
    ack.outcome = Outcome::NO_SUCH_TRACK;
    service_.acknowledge(ack);
    return;
  }
  if (c.kind == Kind::ASK) return answer(block, k, ack);
  if (c.kind == Kind::CORRECT) return correct(block, k, c.label.view(), ack);
  teach_object(block, static_cast<std::uint32_t>(k), c.label.view(), ack,
               static_cast<std::int64_t>(frame_id));
}

}  // namespace orthoflow::graphs
