#include "graphs/nodes/track_memory.hpp"

#include <algorithm>

namespace orthoflow::graphs {

TrackMemories::TrackMemories(std::size_t descriptor_length)
    : length_(descriptor_length),
      tracks_(MAX_OBJECTS),
      key_views_(MAX_OBJECTS * MAX_KEY_VIEWS * descriptor_length) {}

TrackMemory& TrackMemories::of(std::uint32_t track_id, std::uint64_t frame) noexcept {
  TrackMemory* oldest = &tracks_[0];
  for (TrackMemory& t : tracks_) {
    if (t.track_id == track_id) return t;
    if (t.track_id == 0 || t.last_frame < oldest->last_frame) oldest = &t;
  }
  *oldest =
      TrackMemory{};  // reuse the least recently seen entry (tracks are bounded by MAX_OBJECTS)
  oldest->track_id = track_id;
  oldest->last_frame = frame;
  return *oldest;
}

TrackMemory* TrackMemories::find(std::uint32_t track_id) noexcept {
  for (TrackMemory& t : tracks_) {
    if (t.track_id == track_id && track_id != 0) return &t;
  }
  return nullptr;
}

Text TrackMemories::vote(TrackMemory& t, const Text& answer, std::uint32_t smoothing) noexcept {
  t.answers[t.votes++ % smoothing] = answer;
  const std::uint32_t n = std::min(t.votes, smoothing);
  std::uint32_t best_count = 0;
  Text best;
  for (std::uint32_t back = 0; back < n; ++back) {
    const Text& candidate = t.answers[(t.votes - 1 - back) % smoothing];
    std::uint32_t count = 0;
    for (std::uint32_t j = 0; j < n; ++j)
      count += t.answers[j].view() == candidate.view() ? 1U : 0U;
    if (count > best_count) {
      best_count = count;
      best = candidate;
    }
  }
  return best;
}

void TrackMemories::drop_answers(std::string_view label) noexcept {
  for (TrackMemory& t : tracks_) {
    for (Text& answer : t.answers) {
      if (answer.view() == label) answer = Text{};
    }
  }
}

std::span<float> TrackMemories::slot(const TrackMemory& t, std::uint32_t k) noexcept {
  const auto index = static_cast<std::size_t>(&t - tracks_.data());
  return std::span(key_views_)
      .subspan((index * MAX_KEY_VIEWS + k % MAX_KEY_VIEWS) * length_, length_);
}

void TrackMemories::add_key_view(TrackMemory& t, std::span<const float> view) noexcept {
  if (view.size() != length_) return;
  std::copy(view.begin(), view.end(), slot(t, t.key_views).begin());
  ++t.key_views;
  t.untaught = std::min<std::uint32_t>(t.untaught + 1, MAX_KEY_VIEWS);
}

std::size_t TrackMemories::lesson(TrackMemory& t, std::span<const float> current,
                                  bool current_is_key_view, std::span<float> out) noexcept {
  std::size_t n = 0;
  for (std::uint32_t back = t.untaught; back > 0; --back) {  // oldest untaught first
    const auto view = slot(t, t.key_views - back);
    std::copy(view.begin(), view.end(), out.subspan(n++ * length_, length_).begin());
  }
  t.untaught = 0;
  if (!current_is_key_view && current.size() == length_ && n < MAX_TEACH_VIEWS) {
    std::copy(current.begin(), current.end(), out.subspan(n++ * length_, length_).begin());
  }
  return n;
}

}  // namespace orthoflow::graphs
