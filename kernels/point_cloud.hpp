#pragma once
/// @file
/// @brief The point-cloud data model every stage shares: structure of arrays, organized or not,
/// stamped, with 64-byte aligned storage from a std::pmr resource that memory_pool can back.
/// Kernels never take a PointCloud: they take the non-owning views below (STYLE rules 2 and 11).
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory_resource>
#include <span>
#include <vector>

#include "memory_pool/aligned_resource.hpp"

namespace orthoflow::kernels {

/// @brief Read-only view of point coordinates as three parallel spans of equal length.
struct PointsView {
  std::span<const float> x;
  std::span<const float> y;
  std::span<const float> z;
  [[nodiscard]] std::size_t size() const noexcept { return x.size(); }
  [[nodiscard]] bool empty() const noexcept { return x.empty(); }
};

/// @brief Writable view of point coordinates as three parallel spans of equal length.
struct PointsSpan {
  std::span<float> x;
  std::span<float> y;
  std::span<float> z;
  [[nodiscard]] std::size_t size() const noexcept { return x.size(); }
  [[nodiscard]] bool empty() const noexcept { return x.empty(); }
  operator PointsView() const noexcept { return {x, y, z}; }  // NOLINT: implicit by design
};

/// @brief Points plus their image layout: organized when height > 1 (row-major, width x height).
struct CloudView {
  PointsView points;
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  [[nodiscard]] bool organized() const noexcept { return height > 1; }
};

/// @brief Acquisition pose of the sensor (PCD VIEWPOINT): translation and unit quaternion (w, x, y,
/// z).
struct Viewpoint {
  std::array<float, 3> origin{0.0F, 0.0F, 0.0F};
  std::array<float, 4> orientation{1.0F, 0.0F, 0.0F, 0.0F};
  bool operator==(const Viewpoint&) const = default;
};

/// @brief Where and when a frame was taken.
struct FrameInfo {
  std::int64_t sensor_stamp_ns = 0;  ///< device clock, as the source reports it
  std::int64_t host_stamp_ns = 0;    ///< host steady clock when the frame reached orthoflow
  std::uint64_t frame_id = 0;        ///< strictly increasing per source
  Viewpoint viewpoint{};
  /// Where "up" (against gravity) points in the sensor frame, a unit vector, when a source knows it
  /// (the Kinect's accelerometer, a simulated camera's pose); all zero: unknown.
  std::array<float, 3> up{};
  std::uint32_t up_age_ms = 0;  ///< how old the reading behind `up` was when the frame was taken
  bool operator==(const FrameInfo&) const = default;
};

/// @brief Optional per-point fields a cloud may carry besides x, y and z.
enum class Field : std::uint8_t { RGB, LABEL, NORMALS };

/// @brief Owning structure-of-arrays point cloud.
/// @note Every buffer has size() elements; optional fields are either absent (empty) or full size.
/// NaN coordinates mark invalid pixels of an organized cloud. Not thread-safe for concurrent
/// writes.
class PointCloud {
 public:
  template <class T>
  using Buffer = std::pmr::vector<T>;

  /// @brief An empty cloud whose buffers allocate from @p resource (64-byte aligned by default).
  explicit PointCloud(std::pmr::memory_resource* resource = memory_pool::aligned_resource());

  /// @brief Sets the layout to width x height and sizes every present buffer to match.
  /// New elements are zero; height 1 means unorganized; an empty cloud is 0 x 1.
  void resize(std::uint32_t width, std::uint32_t height = 1);
  /// @brief Sizes as unorganized (width = n, height = 1). @pre n <= UINT32_MAX
  void resize_unorganized(std::size_t n);
  /// @brief Adds an optional field, zero-filled to size(). No effect if present.
  void add_field(Field field);
  /// @brief Removes an optional field. No effect if absent.
  void remove_field(Field field);
  [[nodiscard]] bool has(Field field) const noexcept;
  /// @brief Reserves capacity so that resizing up to @p n points does not allocate.
  void reserve(std::size_t n);

  [[nodiscard]] std::size_t size() const noexcept { return x_.size(); }
  [[nodiscard]] bool empty() const noexcept { return x_.empty(); }
  [[nodiscard]] std::uint32_t width() const noexcept { return width_; }
  [[nodiscard]] std::uint32_t height() const noexcept { return height_; }
  [[nodiscard]] bool organized() const noexcept { return height_ > 1; }

  std::span<float> x() noexcept { return x_; }
  std::span<float> y() noexcept { return y_; }
  std::span<float> z() noexcept { return z_; }
  std::span<const float> x() const noexcept { return x_; }
  std::span<const float> y() const noexcept { return y_; }
  std::span<const float> z() const noexcept { return z_; }
  /// @brief Packed colour 0xAARRGGBB (PCL's rgb/rgba layout); empty when absent.
  std::span<std::uint32_t> rgb() noexcept { return rgb_; }
  std::span<const std::uint32_t> rgb() const noexcept { return rgb_; }
  std::span<std::uint32_t> label() noexcept { return label_; }
  std::span<const std::uint32_t> label() const noexcept { return label_; }
  std::span<float> normal_x() noexcept { return nx_; }
  std::span<float> normal_y() noexcept { return ny_; }
  std::span<float> normal_z() noexcept { return nz_; }
  std::span<const float> normal_x() const noexcept { return nx_; }
  std::span<const float> normal_y() const noexcept { return ny_; }
  std::span<const float> normal_z() const noexcept { return nz_; }

  [[nodiscard]] PointsView points() const noexcept { return {x_, y_, z_}; }
  [[nodiscard]] PointsSpan points() noexcept { return {x_, y_, z_}; }
  [[nodiscard]] CloudView view() const noexcept { return {points(), width_, height_}; }

  FrameInfo info{};  ///< stamps, frame id and sensor viewpoint

 private:
  void resize_buffers(std::size_t n);

  std::uint32_t width_ = 0;
  std::uint32_t height_ = 1;
  Buffer<float> x_, y_, z_;
  Buffer<std::uint32_t> rgb_, label_;
  Buffer<float> nx_, ny_, nz_;
  bool has_rgb_ = false;
  bool has_label_ = false;
  bool has_normals_ = false;
};

}  // namespace orthoflow::kernels
