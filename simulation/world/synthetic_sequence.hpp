#pragma once
/// @file
/// @brief Short scripted sequences of synthetic Kinect frames at 30 Hz for tracking tests: objects
/// stand still, slide along the table, appear and disappear, with the ground truth of every frame.
///
/// Each scripted object keeps its id (label OBJECT_LABEL_BASE + id) while it is present. Frames are
/// rendered into a caller-owned cloud; after the first frame, next() touches the heap no more (the
/// present-object list has fixed capacity and the cloud is refilled in place).
#include <cstdint>
#include <vector>

#include "simulation/world/synthetic_scene.hpp"

namespace orthoflow::simulation {

/// @brief One scripted object: present for frames [appear_frame, disappear_frame), sliding at a
/// constant velocity (table coordinates, m/s) from its start pose.
struct ScriptedObject {
  PlacedObject start;
  std::uint64_t appear_frame = 0;
  std::uint64_t disappear_frame = UINT64_MAX;
  double velocity_x = 0.0;
  double velocity_y = 0.0;
  [[nodiscard]] bool present(std::uint64_t frame) const noexcept {
    return frame >= appear_frame && frame < disappear_frame;
  }
};

/// @brief A whole sequence: the table, the objects and the length.
struct SequenceScript {
  TableSpec table;
  std::vector<ScriptedObject> objects;  ///< at most MAX_SCENE_OBJECTS; ids are their indices
  std::uint64_t frames = 60;
};

inline constexpr std::int64_t SEQUENCE_RATE_HZ =
    30;  ///< frame n is stamped n * 1e9 / 30 ns (truncated)

/// @brief Table-plane position of @p object at @p frame (start + velocity * elapsed time).
[[nodiscard]] PlacedObject scripted_pose(const ScriptedObject& object,
                                         std::uint64_t frame) noexcept;

/// @brief The standard script: a random scene of @p objects (>= 3 recommended) where object 0
/// slides across the table (on a path clear of the others), object 1 appears at frames/3, object 2
/// disappears at 2 frames/3, and the rest stand still. Deterministic in @p seed.
/// @pre objects <= MAX_SCENE_OBJECTS
[[nodiscard]] SequenceScript make_sequence_script(std::uint32_t objects, std::uint64_t frames,
                                                  std::uint64_t seed);

/// @brief Plays a script frame by frame. @note Not thread-safe; deterministic in (script, seed).
class SyntheticSequence {
 public:
  /// @pre script.objects.size() <= MAX_SCENE_OBJECTS
  SyntheticSequence(SequenceScript script, std::uint64_t seed, RenderOptions options = {});

  /// @brief Renders the next frame into @p out (stamped: frame_id, sensor and host stamps at 30 Hz)
  /// and updates scene(). @return false, leaving @p out untouched, once the script has ended.
  bool next(kernels::PointCloud& out);

  /// @brief Ground truth of the last frame: the table and the objects present, with their ids.
  [[nodiscard]] const Scene& scene() const noexcept { return scene_; }
  [[nodiscard]] const SequenceScript& script() const noexcept { return script_; }
  /// @brief Frames rendered so far.
  [[nodiscard]] std::uint64_t frames_done() const noexcept { return frame_; }

 private:
  SequenceScript script_;
  RenderOptions options_;
  core::Rng rng_;
  Scene scene_;
  std::uint64_t frame_ = 0;
};

}  // namespace orthoflow::simulation
