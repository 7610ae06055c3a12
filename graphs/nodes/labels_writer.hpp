#pragma once
/// @file
/// @brief LabelsWriter: `orthoflow run --labels-out DIR`: each frame's per-point labels (0 none,
/// 1 table, k >= 2 object k - 2 of the frame's objects: kernels/frame_labels.hpp) written as
/// DIR/frame_<id>.pcd, the organized cloud with a `label` field, without blocking the frame path.
/// The objects node copies the frame into one of a few clouds sized at start-up (no allocation)
/// and hands it to a background thread that encodes and writes it; when every cloud is still
/// being written, the frame's labels are dropped and counted (the frame path never waits for the
/// disk).
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "core/result.hpp"
#include "core/spsc_ring.hpp"
#include "kernels/crop.hpp"
#include "kernels/plane_distance.hpp"
#include "kernels/point_cloud.hpp"

namespace orthoflow::graphs {

class LabelsWriter {
 public:
  /// @brief Creates @p dir (if missing) and @p slots clouds of up to @p max_points points.
  /// Errors name the directory.
  [[nodiscard]] static Result<std::unique_ptr<LabelsWriter>, std::string> open(
      const std::filesystem::path& dir, std::size_t max_points, std::size_t slots = 4);
  ~LabelsWriter();  ///< writes what is queued, then stops
  LabelsWriter(const LabelsWriter&) = delete;
  LabelsWriter& operator=(const LabelsWriter&) = delete;

  /// @brief Queues frame @p frame_id: its points and labels from the segmentation (@p cluster_of
  /// per point, @p slot_of per cluster, frame_labels() with @p plane, @p tau and @p roi). Single
  /// producer, allocation-free, never blocks. Empty @p cluster_of: a frame without a table, every
  /// label 0. @return false when dropped (every cloud busy, an unorganized frame: its labels are
  /// per voxel, not per point; or a frame larger than max_points).
  bool offer(std::uint64_t frame_id, kernels::CloudView cloud, const kernels::Plane& plane,
             float tau, const kernels::AxisBox& roi, std::span<const std::int32_t> cluster_of,
             std::span<const std::int32_t> slot_of) noexcept;
  /// @brief Waits until every queued frame is written (off the frame path).
  void flush() noexcept;
  [[nodiscard]] std::uint64_t written() const noexcept { return written_.load(); }
  [[nodiscard]] std::uint64_t dropped() const noexcept { return dropped_.load(); }
  /// @brief The first write error, or empty (reported once the run ends).
  [[nodiscard]] std::string first_error() const;

 private:
  LabelsWriter(std::filesystem::path dir, std::size_t max_points, std::size_t slots);
  void loop() noexcept;
  bool drain() noexcept;
  std::filesystem::path dir_;
  std::size_t max_points_;
  std::vector<kernels::PointCloud> clouds_;
  core::SpscRing<std::uint32_t> free_, full_;  // cloud indices: to the frame path, to the writer
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> written_{0}, dropped_{0}, queued_{0};
  mutable std::mutex error_mutex_;
  std::string first_error_;  // guarded by error_mutex_
  std::thread thread_;
};

}  // namespace orthoflow::graphs
