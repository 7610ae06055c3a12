#pragma once
/// @file
/// @brief SessionLog, what the `session_log` sink (graphs/nodes/session_log_node.hpp) feeds: it
/// counts what the graph did (the summary `orthoflow run` prints), scores the answers against the
/// ground truth when the source knows it, writes one JSON line per frame through a LineWriter, and
/// keeps the last frame with objects for the snapshot picture. Scoring: an object whose true
/// category has been taught is right when labelled with it; an object whose category has not been
/// taught yet is right when answered Unknown.
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "graphs/frame/frame_block.hpp"
#include "graphs/services/line_writer.hpp"

namespace orthoflow::graphs {

/// @brief Right / asked counter.
struct Score {
  std::uint64_t right = 0, asked = 0;
  [[nodiscard]] double rate() const noexcept {
    return asked == 0 ? 0.0 : static_cast<double>(right) / static_cast<double>(asked);
  }
};

/// @brief What a run did, for the summary.
struct SessionSummary {
  std::uint64_t frames = 0, frames_with_table = 0, frames_with_error = 0;
  std::uint64_t object_views = 0, key_views = 0, recognitions = 0, teaches = 0;
  std::uint32_t tracks_started = 0;
  Score before_teaching;  ///< category not taught yet: Unknown is right
  Score after_teaching;   ///< category taught: its label is right
  Score new_instances;    ///< subset of after_teaching: instances that were never taught themselves
  std::vector<std::string> taught;  ///< labels taught, in teaching order
  FrameError first_error;           ///< the first error a frame reported (empty: none)
  std::uint64_t first_error_frame = 0;
};

/// @brief The last frame with objects, in table-plane coordinates, for a top-view picture.
struct SceneSnapshot {
  std::uint64_t frame_id = 0;
  bool valid = false;
  kernels::Plane plane{};
  std::vector<double> hull_u, hull_v;  ///< table polygon
  std::vector<float> x, y, z;          ///< object points (subsampled), sensor frame
  std::vector<ObjectRecord> objects;
};

/// @brief The sink's shared results. Read after the run (not while it runs).
class SessionLog {
 public:
  /// @brief @p json may be null (no JSON lines).
  explicit SessionLog(std::unique_ptr<LineWriter> json = nullptr);
  [[nodiscard]] const SessionSummary& summary() const noexcept { return summary_; }
  [[nodiscard]] const SceneSnapshot& snapshot() const noexcept { return snapshot_; }
  [[nodiscard]] LineWriter* json() const noexcept { return json_.get(); }
  /// @brief Records one frame (the sink node calls it; also usable directly in tests).
  void record(const FrameBlock& block, std::uint64_t frame_id) noexcept;

 private:
  void score(const ObjectRecord& o) noexcept;
  void write_json(const FrameBlock& block, std::uint64_t frame_id) noexcept;
  void keep_snapshot(const FrameBlock& block, std::uint64_t frame_id) noexcept;
  [[nodiscard]] bool was_taught(std::string_view category) const noexcept;

  std::unique_ptr<LineWriter> json_;
  SessionSummary summary_;
  SceneSnapshot snapshot_;
  std::vector<std::uint32_t> taught_instances_;  // truth labels of taught objects (reserved)
  std::vector<char> line_;                       // JSON line buffer (reserved)
};

}  // namespace orthoflow::graphs
