#include "graphs/frame/frame_block.hpp"

#include "engine/ipc_frame_ref.hpp"

#include <algorithm>
#include <cstring>
#include <new>

namespace orthoflow::graphs {

namespace {

constexpr std::size_t ALIGN = 64;
constexpr std::size_t align_up(std::size_t n) noexcept { return (n + ALIGN - 1) / ALIGN * ALIGN; }

// Byte offsets of every region for a given capacity; `end` is the block size needed.
struct Layout {
  std::size_t state = 0, voxels = 0, hull = 0, objects = 0, descriptors = 0, end = 0;
};

Layout layout(std::size_t capacity, std::size_t room) noexcept {
  const std::size_t floats = align_up(capacity * sizeof(float));
  Layout l;
  // the raw frame with every optional field (rgb and label), as frame_payload lays it out
  l.state = align_up(sizeof(engine::FrameHeader) + 3 * floats +
                     2 * align_up(capacity * sizeof(std::uint32_t)));
  l.voxels = l.state + align_up(sizeof(FrameState));
  l.hull = l.voxels + 3 * floats;
  l.objects = l.hull + 2 * align_up(MAX_HULL * sizeof(double));
  l.descriptors = l.objects + 3 * floats;
  l.end = l.descriptors + align_up(MAX_OBJECTS * room * sizeof(float));
  return l;
}

template <class T>
std::span<T> at(std::byte* base, std::size_t offset, std::size_t n) noexcept {
  return {reinterpret_cast<T*>(base + offset), n};  // NOLINT: regions are aligned by layout()
}

kernels::PointsSpan xyz_at(std::byte* base, std::size_t offset, std::size_t capacity) noexcept {
  const std::size_t stride = align_up(capacity * sizeof(float));
  return {at<float>(base, offset, capacity), at<float>(base, offset + stride, capacity),
          at<float>(base, offset + 2 * stride, capacity)};
}

}  // namespace

std::size_t FrameBlock::room_in(std::size_t block_bytes, std::size_t capacity) noexcept {
  const std::size_t start = layout(capacity, 0).descriptors;
  if (block_bytes <= start) return 0;
  return (block_bytes - start) / (MAX_OBJECTS * sizeof(float)) / DESCRIPTOR_ALIGN *
         DESCRIPTOR_ALIGN;
}

std::size_t FrameBlock::bytes_for(std::size_t capacity, std::size_t room) noexcept {
  return layout(capacity, room).end;
}

std::size_t FrameBlock::capacity_for(std::size_t block_bytes, std::size_t room) noexcept {
  // bytes_for is increasing in capacity: binary search the largest fitting value
  std::size_t lo = 0;
  std::size_t hi = block_bytes / (8 * sizeof(float)) + 1;
  while (lo < hi) {
    const std::size_t mid = lo + (hi - lo + 1) / 2;
    if (bytes_for(mid, room) <= block_bytes) {
      lo = mid;
    } else {
      hi = mid - 1;
    }
  }
  return lo;
}

FrameBlock::FrameBlock(std::span<std::byte> block, std::size_t capacity) noexcept
    : capacity_(capacity), room_(room_in(block.size(), capacity)) {
  const Layout l = layout(capacity, room_);
  std::byte* base = block.data();
  raw_ = block.first(l.state);
  // FrameState is an implicit-lifetime aggregate of trivially copyable parts; the block outlives
  // it.
  state_ = std::launder(reinterpret_cast<FrameState*>(base + l.state));  // NOLINT
  voxels_ = xyz_at(base, l.voxels, capacity);
  hull_u_ = at<double>(base, l.hull, MAX_HULL);
  hull_v_ = at<double>(base, l.hull + align_up(MAX_HULL * sizeof(double)), MAX_HULL);
  object_points_ = xyz_at(base, l.objects, capacity);
  descriptors_ = at<float>(base, l.descriptors, MAX_OBJECTS * room_);
}

Result<engine::FrameView, engine::FrameError> FrameBlock::frame() const noexcept {
  return engine::view_frame(engine::resolve_frame_bytes(raw_));  // in the block, or in an IPC chunk
}

bool FrameBlock::external() const noexcept {
  return engine::resolve_frame_bytes(raw_).data() != raw_.data();
}

kernels::PointsView FrameBlock::object_view(std::size_t i) const noexcept {
  const ObjectRecord& o = state_->objects[i];
  return {std::span<const float>(object_points_.x).subspan(o.first, o.count),
          std::span<const float>(object_points_.y).subspan(o.first, o.count),
          std::span<const float>(object_points_.z).subspan(o.first, o.count)};
}

std::span<float> FrameBlock::descriptor(std::size_t i) const noexcept {
  return descriptors_.subspan(i * room_, room_);
}

}  // namespace orthoflow::graphs
