#pragma once
/// @file
/// @brief What the recognise node remembers of each track: the answers it smooths over (majority of
/// the last `smoothing`) and the track's key views (thesis Table 3.1: the views taken when tracking
/// started and when the object is static again after moving), so that teaching a track stores those
/// views, not only the current frame's. All memory is sized at construction; nothing allocates
/// afterwards.
#include <array>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "graphs/frame/frame_block.hpp"
#include "graphs/services/learning_service.hpp"

namespace orthoflow::graphs {

inline constexpr std::size_t MAX_VOTES = 16;  ///< answers a track can smooth over
inline constexpr std::size_t MAX_KEY_VIEWS =
    MAX_TEACH_VIEWS - 1;  ///< newest key views kept per track

/// @brief One track's memory. @note track_id 0 marks a free entry.
struct TrackMemory {
  std::uint32_t track_id = 0;
  std::uint64_t last_frame = 0;
  std::uint32_t age = 0;    ///< frames it was recognised in
  std::uint32_t votes = 0;  ///< answers recorded (ring position)
  std::array<Text, MAX_VOTES> answers{};
  std::uint32_t key_views =
      0;  ///< key views recorded (ring position; the newest MAX_KEY_VIEWS are kept)
  std::uint32_t untaught = 0;  ///< how many of the newest kept key views no teach has stored yet
  // The answer of the track's last ask, shown in the frames the recognise node's period skips.
  bool asked = false;         ///< the learner was asked about this track at least once
  std::int64_t asked_ns = 0;  ///< stamp of the frame of that ask
  Text label;                 ///< its smoothed answer (empty: Unknown)
  float score = 0.0F;
  Text nearest, runner_up;
  float runner_up_score = 0.0F;
};

/// @brief The memories of up to MAX_OBJECTS tracks (the least recently seen is reused).
/// @note Not thread-safe: the recognise node's (concurrency 1).
class TrackMemories {
 public:
  /// @brief Room for MAX_KEY_VIEWS views of @p descriptor_length values per track.
  explicit TrackMemories(std::size_t descriptor_length);
  /// @brief The memory of @p track_id, made (reusing the least recently seen entry) when new.
  TrackMemory& of(std::uint32_t track_id, std::uint64_t frame) noexcept;
  /// @brief The memory of @p track_id, or nullptr.
  [[nodiscard]] TrackMemory* find(std::uint32_t track_id) noexcept;
  /// @brief Records one answer (empty = Unknown) and @return the majority of the last @p smoothing
  /// answers (ties: the most recent).
  Text vote(TrackMemory& t, const Text& answer, std::uint32_t smoothing) noexcept;
  /// @brief Forgets the recorded answers of @p t (after a correction: the next answers are the new
  /// ones).
  static void reset_votes(TrackMemory& t) noexcept { t.votes = 0; }
  /// @brief Forgets every recorded answer equal to @p label (after the category was forgotten).
  void drop_answers(std::string_view label) noexcept;
  /// @brief Keeps @p view (descriptor_length values) as the newest key view of @p t.
  void add_key_view(TrackMemory& t, std::span<const float> view) noexcept;
  /// @brief The views a teach of @p t stores, row-major into @p out: its key views no teach has
  /// stored yet (oldest first), then @p current unless @p current_is_key_view (it is the newest key
  /// view then). Marks those key views taught. @pre out holds MAX_TEACH_VIEWS views. @return the
  /// number of views.
  std::size_t lesson(TrackMemory& t, std::span<const float> current, bool current_is_key_view,
                     std::span<float> out) noexcept;

 private:
  [[nodiscard]] std::span<float> slot(const TrackMemory& t, std::uint32_t k) noexcept;
  std::size_t length_;
  std::vector<TrackMemory> tracks_;
  std::vector<float> key_views_;  // MAX_OBJECTS x MAX_KEY_VIEWS x length
};

}  // namespace orthoflow::graphs
