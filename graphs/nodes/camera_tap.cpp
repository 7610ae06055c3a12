#include "graphs/nodes/camera_tap.hpp"

#include <algorithm>

namespace orthoflow::graphs {

void CameraTap::request(std::int64_t now_ns, std::int64_t period_ns, std::int64_t keep_ns) {
  {
    std::lock_guard<std::mutex> guard(lock_);
    if (!allocated_) {
      const std::size_t n = static_cast<std::size_t>(max_width_) * max_height_;
      image_.x.assign(n, 0.0F);
      image_.y.assign(n, 0.0F);
      image_.z.assign(n, 0.0F);
      image_.rgb.reserve(n);
      allocated_ = true;
    }
  }
  period_ns_.store(std::max<std::int64_t>(0, period_ns));
  wanted_until_ns_.store(now_ns + std::max<std::int64_t>(0, keep_ns));
}

bool CameraTap::offer(const engine::FrameView& frame, std::int64_t now_ns) noexcept {
  if (now_ns >= wanted_until_ns_.load(std::memory_order_relaxed)) return false;
  if (last_copy_ns_ != 0 && now_ns - last_copy_ns_ < period_ns_.load(std::memory_order_relaxed))
    return false;
  const kernels::CloudView& cloud = frame.cloud;
  if (!cloud.organized() || cloud.width == 0 || max_width_ == 0 || max_height_ == 0) return false;
  std::unique_lock<std::mutex> guard(lock_, std::try_to_lock);
  if (!guard.owns_lock()) {
    busy_.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  if (!allocated_) return false;
  const std::uint32_t step = std::max((cloud.width + max_width_ - 1) / max_width_,
                                      (cloud.height + max_height_ - 1) / max_height_);
  const std::uint32_t w = cloud.width / step, h = cloud.height / step;
  const bool colour = frame.rgb.size() == cloud.points.x.size();
  image_.frame_id = frame.header->frame_id;
  image_.width = w;
  image_.height = h;
  image_.step = step;
  image_.rgb.resize(colour ? static_cast<std::size_t>(w) * h : 0);  // within the reserved capacity
  std::size_t k = 0;
  for (std::uint32_t j = 0; j < h; ++j) {
    const std::size_t row = static_cast<std::size_t>(j) * step * cloud.width;
    for (std::uint32_t i = 0; i < w; ++i, ++k) {
      const std::size_t p = row + static_cast<std::size_t>(i) * step;
      image_.x[k] = cloud.points.x[p];
      image_.y[k] = cloud.points.y[p];
      image_.z[k] = cloud.points.z[p];
      if (colour) image_.rgb[k] = frame.rgb[p];
    }
  }
  last_copy_ns_ = now_ns;
  copied_.fetch_add(1, std::memory_order_relaxed);
  return true;
}

bool CameraTap::take(CameraImage& out, std::uint64_t newer_than) {
  std::lock_guard<std::mutex> guard(lock_);
  if (!allocated_ || image_.width == 0 || image_.frame_id <= newer_than) return false;
  const std::size_t n = static_cast<std::size_t>(image_.width) * image_.height;
  out.frame_id = image_.frame_id;
  out.width = image_.width;
  out.height = image_.height;
  out.step = image_.step;
  out.x.assign(image_.x.begin(), image_.x.begin() + static_cast<std::ptrdiff_t>(n));
  out.y.assign(image_.y.begin(), image_.y.begin() + static_cast<std::ptrdiff_t>(n));
  out.z.assign(image_.z.begin(), image_.z.begin() + static_cast<std::ptrdiff_t>(n));
  out.rgb = image_.rgb;
  return true;
}

}  // namespace orthoflow::graphs
