#pragma once
/// @file
/// @brief CameraTap: the camera's view for a viewer (the web view's camera image), taken off the
/// frame path without slowing it. The objects_output node offers every frame; the tap copies a
/// downsampled view of an organized frame (points and colour, every step-th pixel of every step-th
/// row, at most max_width x max_height) only while a viewer has asked for images recently and no
/// faster than the viewer asked. The copy goes into buffers allocated when the viewer first asked,
/// under a mutex the frame path only try-locks: a viewer copying the image out makes that frame
/// skip the tap, never wait. Unorganized frames (height 1) have no camera view and are skipped.
#include <atomic>
#include <cstdint>
#include <mutex>
#include <vector>

#include "engine/frame_payload.hpp"

namespace orthoflow::graphs {

/// @brief A downsampled camera view: pixel (i, j) of the image is pixel (i * step, j * step) of the
/// frame. x, y, z in the sensor frame (metres, NaN where the sensor measured nothing); rgb as the
/// frame carries it (0xAARRGGBB), empty when the frame has no colour.
struct CameraImage {
  std::uint64_t frame_id = 0;
  std::uint32_t width = 0, height = 0;
  std::uint32_t step = 1;
  std::vector<float> x, y, z;
  std::vector<std::uint32_t> rgb;
};

class CameraTap {
 public:
  /// @brief Images of at most @p max_width x @p max_height pixels (the frame is subsampled by the
  /// smallest integer step that fits).
  explicit CameraTap(std::uint32_t max_width = 320, std::uint32_t max_height = 240) noexcept
      : max_width_(max_width), max_height_(max_height) {}

  /// @brief Viewer side: asks for images at most every @p period_ns for the next @p keep_ns (ask
  /// again to keep them coming). Allocates the buffers the first time. Thread-safe.
  void request(std::int64_t now_ns, std::int64_t period_ns, std::int64_t keep_ns);

  /// @brief Frame path: copies @p frame when asked for and due. Never blocks, never allocates.
  /// @return whether it was copied.
  bool offer(const engine::FrameView& frame, std::int64_t now_ns) noexcept;

  /// @brief Viewer side: copies the newest image into @p out when its frame id is above
  /// @p newer_than. Thread-safe (allocates in @p out).
  bool take(CameraImage& out, std::uint64_t newer_than);

  /// @brief Whether a viewer has asked for images that are still wanted at @p now_ns.
  [[nodiscard]] bool wanted(std::int64_t now_ns) const noexcept {
    return now_ns < wanted_until_ns_.load(std::memory_order_relaxed);
  }

  /// @brief Images copied, and frames that skipped the tap because a viewer was copying.
  [[nodiscard]] std::uint64_t copied() const noexcept { return copied_.load(); }
  [[nodiscard]] std::uint64_t busy() const noexcept { return busy_.load(); }

 private:
  std::uint32_t max_width_, max_height_;
  std::atomic<std::int64_t> wanted_until_ns_{0};
  std::atomic<std::int64_t> period_ns_{0};
  std::int64_t last_copy_ns_ = 0;  // frame path only
  std::atomic<std::uint64_t> copied_{0}, busy_{0};
  std::mutex lock_;  // guards image_; the frame path only try-locks it
  CameraImage image_;
  bool allocated_ = false;  // guarded by lock_
};

}  // namespace orthoflow::graphs
