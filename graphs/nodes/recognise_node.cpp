// The `recognise` kind: asks the learner for every described object, smooths the answers per track,
// keeps each track's key views (graphs/nodes/track_memory.hpp), applies the learning channel's
// commands (graphs/nodes/learning_commands.hpp) and, with instructor: 1, the scripted instructor of
// the synthetic session.
#include "graphs/nodes/recognise_node.hpp"

#include <algorithm>
#include <vector>

#include "graphs/nodes/learning_commands.hpp"
#include "graphs/nodes/node_support.hpp"
#include "graphs/nodes/session_script.hpp"
#include "graphs/nodes/track_memory.hpp"

namespace orthoflow::graphs {

namespace {

using engine::Message;

const engine::PortSpec PORTS[] = {FRAME_IN, FRAME_OUT};
constexpr std::size_t MAX_CATEGORIES = 32;  // categories the instructor keeps track of
constexpr std::size_t MAX_COMMANDS_PER_FRAME =
    64;  // commands applied per frame at most (the rest wait)
constexpr std::array<std::uint32_t, 3> INSTRUCTOR_AGES{5, 15,
                                                       25};  // track ages (frames) it teaches at

struct RecogniseParams {
  std::uint32_t smoothing = 5;
  bool instructor = false;
  /// A track is asked about again only this long after its last ask (0: every frame), unless its
  /// view is a key view or a lesson changed the memory since; between asks it keeps its answer.
  std::int64_t period_ns = 0;
};

/// The instructor's record of one category: the track it teaches it from.
struct InstructorEntry {
  Text category;
  std::uint32_t track_id = 0;
};

class Recognise final : public engine::Node {
 public:
  Recognise(std::size_t capacity, const RecogniseParams& p, LearningService& service)
      : capacity_(capacity),
        p_(p),
        service_(service),
        memories_(service.descriptor_length()),
        desk_(service, memories_) {
    service.learner().prepare(scratch_);  // Local LDA's topic scratch, sized once
  }
  std::span<const engine::PortSpec> inputs() const noexcept override { return {PORTS, 1}; }
  std::span<const engine::PortSpec> outputs() const noexcept override { return {PORTS + 1, 1}; }
  bool stateful() const noexcept override { return true; }

  void process(const Message& in, engine::Emitter& out) noexcept override {
    const FrameBlock block = block_of(in, capacity_);
    FrameState& s = block.state();
    auto frame = block.frame();
    const std::int64_t stamp = frame ? frame->header->sensor_stamp_ns : in.stamp_ns;
    const bool ask_all = memory_changed_;  // a lesson of the last frame may change every answer
    memory_changed_ = false;
    for (std::uint32_t k = 0; k < s.object_count; ++k)
      recognise(block, k, in.frame_id, stamp, ask_all);
    LearningCommand command;
    for (std::size_t n = 0; n < MAX_COMMANDS_PER_FRAME && service_.poll(command); ++n) {
      desk_.apply(block, command, in.frame_id);
      memory_changed_ = memory_changed_ || command.kind != LearningCommand::Kind::ASK;
    }
    if (p_.instructor) instruct(block, in.frame_id);
    out.emit(0, in);
  }

 private:
  /// True if the track's answer from its last ask still stands in the frame stamped @p stamp.
  [[nodiscard]] bool carries(const TrackMemory* t, const ObjectRecord& o, std::int64_t stamp,
                             bool ask_all) const noexcept {
    return p_.period_ns > 0 && t != nullptr && t->asked && !ask_all && !o.key_view &&
           stamp >= t->asked_ns && stamp - t->asked_ns < p_.period_ns;
  }

  void recognise(const FrameBlock& block, std::uint32_t k, std::uint64_t frame, std::int64_t stamp,
                 bool ask_all) noexcept {
    ObjectRecord& o = block.state().objects[k];
    if (o.fragment || !o.described || o.descriptor_length != service_.descriptor_length()) return;
    const auto descriptor = block.descriptor(k).first(o.descriptor_length);
    if (TrackMemory* known = o.track_id == 0 ? nullptr : memories_.find(o.track_id);
        carries(known, o, stamp, ask_all)) {
      known->last_frame = frame;
      ++known->age;
      o.carried = true;
      o.label = known->label;
      o.unknown = known->label.empty();
      o.score = known->score;
      o.nearest = known->nearest;
      o.runner_up = known->runner_up;
      o.runner_up_score = known->runner_up_score;
      return;
    }
    const auto prediction = service_.learner().ask(descriptor, scratch_);
    o.recognised = true;
    o.score = prediction.score;
    o.runner_up.assign(prediction.runner_up.view());
    o.runner_up_score = prediction.runner_up_score;
    o.nearest.assign(prediction.label.view());
    Text answer;
    if (!prediction.unknown) answer.assign(prediction.label.view());
    if (o.track_id == 0) {  // untracked: no smoothing, no key views
      o.label = answer;
      o.unknown = answer.empty();
      return;
    }
    TrackMemory& t = memories_.of(o.track_id, frame);
    t.last_frame = frame;
    ++t.age;
    if (o.key_view) memories_.add_key_view(t, descriptor);
    o.label = memories_.vote(t, answer, p_.smoothing);
    o.unknown = o.label.empty();
    t.asked = true;
    t.asked_ns = stamp;
    t.label = o.label;
    t.score = o.score;
    t.nearest = o.nearest;
    t.runner_up = o.runner_up;
    t.runner_up_score = o.runner_up_score;
  }

  void instruct(const FrameBlock& block, std::uint64_t frame) noexcept {
    const FrameState& s = block.state();
    for (std::uint32_t k = 0; k < s.object_count; ++k) {
      const ObjectRecord& o = s.objects[k];
      if (o.track_id == 0 || o.truth_category.empty() ||
          !instructor_teaches(o.truth_category.view()))
        continue;
      InstructorEntry* entry = nullptr;
      for (std::size_t c = 0; c < categories_used_ && entry == nullptr; ++c) {
        if (categories_[c].category.view() == o.truth_category.view()) entry = &categories_[c];
      }
      if (entry == nullptr && categories_used_ < MAX_CATEGORIES) {
        entry = &categories_[categories_used_++];
        entry->category = o.truth_category;
        entry->track_id = o.track_id;  // the first instance the instructor sees of this category
      }
      if (entry == nullptr || entry->track_id != o.track_id) continue;
      const TrackMemory* t = memories_.find(o.track_id);
      if (t != nullptr && std::find(INSTRUCTOR_AGES.begin(), INSTRUCTOR_AGES.end(), t->age) !=
                              INSTRUCTOR_AGES.end()) {
        (void)desk_.teach_object(block, k, o.truth_category.view(), LearningAck{},
                                 static_cast<std::int64_t>(frame));
        memory_changed_ = true;
      }
    }
  }

  std::size_t capacity_;
  RecogniseParams p_;
  LearningService& service_;
  learning::AskScratch scratch_;
  TrackMemories memories_;
  LessonDesk desk_;
  std::array<InstructorEntry, MAX_CATEGORIES> categories_{};
  std::size_t categories_used_ = 0;
  bool memory_changed_ = false;  // a lesson was applied in the last frame: ask every track again
};

}  // namespace

void add_recognise_node(engine::NodeRegistry& registry, LearningService& service) {
  registry.add(
      "recognise",
      "asks the learner per object, smooths per track, keeps key views, applies the learning "
      "channel's "
      "commands: smoothing (answers), instructor=0|1 (scripted teacher of the synthetic session), "
      "period_ms (ask each track at most this often, 0 = every frame; key views and lessons ask "
      "again at once)",
      [&service](const engine::ParamMap& params, const engine::NodeContext& context) -> NodeResult {
        auto capacity = frame_capacity(context);
        if (!capacity) return err(capacity.error());
        if (auto ok = params.only({"smoothing", "instructor", "period_ms"}); !ok)
          return err(ok.error());
        RecogniseParams p;
        std::string e;
        std::int64_t instructor = 0;
        double period_ms = 0.0;
        take(params.integer("smoothing", p.smoothing, 1, MAX_VOTES), p.smoothing, e);
        take(params.integer("instructor", 0, 0, 1), instructor, e);
        take(params.number("period_ms", 0.0, 0.0, 60000.0), period_ms, e);
        if (!e.empty()) return err(e);
        p.instructor = instructor == 1;
        p.period_ns = static_cast<std::int64_t>(period_ms * 1e6);
        return std::unique_ptr<engine::Node>(new Recognise(*capacity, p, service));
      });
}

}  // namespace orthoflow::graphs
