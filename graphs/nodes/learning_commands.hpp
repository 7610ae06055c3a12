#pragma once
/// @file
/// @brief LessonDesk: the recognise node's side of the learning channel. It applies one command to
/// the objects of the frame the node has just recognised (teach a track or the object at a position
/// with its key views, correct a track with its current view, forget a category, answer an ask),
/// and acknowledges it to its sender through the LearningService. Also teaches for the scripted
/// instructor.
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "graphs/frame/frame_block.hpp"
#include "graphs/nodes/track_memory.hpp"
#include "graphs/services/learning_service.hpp"

namespace orthoflow::graphs {

/// @note Not thread-safe: the recognise node's (concurrency 1). Allocates only at construction.
class LessonDesk {
 public:
  LessonDesk(LearningService& service, TrackMemories& memories);
  /// @brief Teaches object @p k of @p block as @p label with its lesson views
  /// (TrackMemories::lesson); marks the record taught. @return the acknowledgement (sent when
  /// ack.sequence != 0).
  LearningAck teach_object(const FrameBlock& block, std::uint32_t k, std::string_view label,
                           LearningAck ack, std::int64_t stamp) noexcept;
  /// @brief Applies @p command to the objects of @p block (frame @p frame_id) and acknowledges it.
  void apply(const FrameBlock& block, const LearningCommand& command,
             std::uint64_t frame_id) noexcept;

 private:
  [[nodiscard]] bool described(const ObjectRecord& o, LearningAck& ack) noexcept;
  [[nodiscard]] std::int64_t find_object(const FrameState& s,
                                         const LearningCommand& c) const noexcept;
  void answer(const FrameBlock& block, std::int64_t k, LearningAck ack) noexcept;
  void correct(const FrameBlock& block, std::int64_t k, std::string_view label,
               LearningAck ack) noexcept;
  LearningService& service_;
  TrackMemories& memories_;
  std::vector<float> lesson_;  // MAX_TEACH_VIEWS views
};

}  // namespace orthoflow::graphs
