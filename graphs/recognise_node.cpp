#include "graphs/recognise_node.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "graphs/node_support.hpp"
#include "graphs/session_script.hpp"

namespace orthoflow::graphs {

namespace {

using engine::Message;

const engine::PortSpec PORTS[] = {FRAME_IN, FRAME_OUT};
constexpr std::size_t MAX_VOTES = 16;
constexpr std::size_t MAX_CATEGORIES = 32;  // categories the instructor keeps track of
constexpr std::array<std::uint32_t, 3> INSTRUCTOR_AGES{5, 15, 25};  // track ages (frames) it teaches at

struct RecogniseParams {
  std::uint32_t smoothing = 5;
  bool instructor = false;
};

/// What the node remembers of one track.
struct TrackMemory {
  std::uint32_t track_id = 0;  // 0 = free entry
  std::uint64_t last_frame = 0;
  std::uint32_t age = 0;
  std::uint32_t votes = 0;  // answers recorded (ring position)
  std::array<Text, MAX_VOTES> answers{};
};

/// The instructor's record of one category: the track it teaches it from.
struct InstructorEntry {
  Text category;
  std::uint32_t track_id = 0;
};

class Recognise final : public engine::Node {
 public:
  Recognise(std::size_t capacity, const RecogniseParams& p, LearningService& service)
      : capacity_(capacity), p_(p), service_(service), tracks_(MAX_OBJECTS) {}
  std::span<const engine::PortSpec> inputs() const noexcept override { return {PORTS, 1}; }
  std::span<const engine::PortSpec> outputs() const noexcept override { return {PORTS + 1, 1}; }
  bool stateful() const noexcept override { return true; }

  void process(const Message& in, engine::Emitter& out) noexcept override {
    const FrameBlock block = block_of(in, capacity_);
    FrameState& s = block.state();
    for (std::uint32_t k = 0; k < s.object_count; ++k) recognise(block, k, in.frame_id);
    LearningEvent event;
    while (service_.poll(event)) apply(block, event, in.frame_id);
    if (p_.instructor) instruct(block, in.frame_id);
    out.emit(0, in);
  }

 private:
  TrackMemory* memory_of(std::uint32_t track_id, std::uint64_t frame) noexcept {
    TrackMemory* oldest = &tracks_[0];
    for (TrackMemory& t : tracks_) {
      if (t.track_id == track_id) return &t;
      if (t.last_frame < oldest->last_frame || t.track_id == 0) oldest = &t;
    }
    *oldest = TrackMemory{};  // reuse the least recently seen entry (tracks are bounded by MAX_OBJECTS)
    oldest->track_id = track_id;
    oldest->last_frame = frame;
    return oldest;
  }

  void recognise(const FrameBlock& block, std::uint32_t k, std::uint64_t frame) noexcept {
    ObjectRecord& o = block.state().objects[k];
    if (o.fragment || !o.described || o.descriptor_length != service_.descriptor_length()) return;
    const auto prediction = service_.learner().ask(block.descriptor(k).first(o.descriptor_length), scratch_);
    o.recognised = true;
    o.score = prediction.score;
    o.runner_up.assign(prediction.runner_up.view());
    o.nearest.assign(prediction.label.view());
    Text answer;
    if (!prediction.unknown) answer.assign(prediction.label.view());
    if (o.track_id == 0) {  // untracked: no smoothing
      o.label = answer;
      o.unknown = answer.empty();
      return;
    }
    TrackMemory& t = *memory_of(o.track_id, frame);
    t.last_frame = frame;
    ++t.age;
    t.answers[t.votes++ % p_.smoothing] = answer;
    o.label = majority(t);
    o.unknown = o.label.empty();
  }

  // The most frequent answer among the track's last `smoothing` answers (ties: the most recent).
  [[nodiscard]] Text majority(const TrackMemory& t) const noexcept {
    const std::uint32_t n = std::min(t.votes, p_.smoothing);
    std::uint32_t best_count = 0;
    Text best;
    for (std::uint32_t back = 0; back < n; ++back) {
      const Text& candidate = t.answers[(t.votes - 1 - back) % p_.smoothing];
      std::uint32_t count = 0;
      for (std::uint32_t j = 0; j < n; ++j) count += t.answers[j].view() == candidate.view() ? 1U : 0U;
      if (count > best_count) {
        best_count = count;
        best = candidate;
      }
    }
    return best;
  }

  void teach_object(const FrameBlock& block, std::uint32_t k, std::string_view label, std::int64_t stamp) noexcept {
    ObjectRecord& o = block.state().objects[k];
    if (!o.described || label.empty()) return;
    o.taught = service_.teach(label, block.descriptor(k).first(o.descriptor_length), o.track_id, stamp);
    if (o.taught) o.taught_as.assign(label);
  }

  void apply(const FrameBlock& block, const LearningEvent& e, std::uint64_t frame) noexcept {
    const FrameState& s = block.state();
    std::int64_t best = -1;
    float best_d = 1e30F;
    for (std::uint32_t k = 0; k < s.object_count; ++k) {
      const ObjectRecord& o = s.objects[k];
      if (e.kind == LearningEvent::Kind::TEACH_TRACK) {
        if (o.track_id == e.track_id) best = k;
        continue;
      }
      const float dx = o.stats.centroid[0] - e.position[0], dy = o.stats.centroid[1] - e.position[1],
                  dz = o.stats.centroid[2] - e.position[2];
      const float d = std::sqrt(dx * dx + dy * dy + dz * dz);
      if (d < best_d) {
        best_d = d;
        best = k;
      }
    }
    if (best >= 0) teach_object(block, static_cast<std::uint32_t>(best), e.label.view(), static_cast<std::int64_t>(frame));
  }

  void instruct(const FrameBlock& block, std::uint64_t frame) noexcept {
    const FrameState& s = block.state();
    for (std::uint32_t k = 0; k < s.object_count; ++k) {
      const ObjectRecord& o = s.objects[k];
      if (o.track_id == 0 || o.truth_category.empty() || !instructor_teaches(o.truth_category.view())) continue;
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
      const TrackMemory* t = find(o.track_id);
      if (t != nullptr && std::find(INSTRUCTOR_AGES.begin(), INSTRUCTOR_AGES.end(), t->age) != INSTRUCTOR_AGES.end()) {
        teach_object(block, k, o.truth_category.view(), static_cast<std::int64_t>(frame));
      }
    }
  }

  [[nodiscard]] const TrackMemory* find(std::uint32_t track_id) const noexcept {
    for (const TrackMemory& t : tracks_) {
      if (t.track_id == track_id) return &t;
    }
    return nullptr;
  }

  std::size_t capacity_;
  RecogniseParams p_;
  LearningService& service_;
  learning::AskScratch scratch_;
  std::vector<TrackMemory> tracks_;
  std::array<InstructorEntry, MAX_CATEGORIES> categories_{};
  std::size_t categories_used_ = 0;
};

}  // namespace

void add_recognise_node(engine::NodeRegistry& registry, LearningService& service) {
  registry.add("recognise",
               "asks the learner per object, smooths per track, applies teach events: smoothing (answers), "
               "instructor=0|1 (scripted teacher of the synthetic session)",
               [&service](const engine::ParamMap& params, const engine::NodeContext& context) -> NodeResult {
                 auto capacity = frame_capacity(context);
                 if (!capacity) return err(capacity.error());
                 if (auto ok = params.only({"smoothing", "instructor"}); !ok) return err(ok.error());
                 RecogniseParams p;
                 std::string e;
                 std::int64_t instructor = 0;
                 take(params.integer("smoothing", p.smoothing, 1, MAX_VOTES), p.smoothing, e);
                 take(params.integer("instructor", 0, 0, 1), instructor, e);
                 if (!e.empty()) return err(e);
                 p.instructor = instructor == 1;
                 return std::unique_ptr<engine::Node>(new Recognise(*capacity, p, service));
               });
}

}  // namespace orthoflow::graphs
