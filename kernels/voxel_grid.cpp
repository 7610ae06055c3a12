#include "kernels/voxel_grid.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>

#include "kernels/cloud_stats.hpp"
#include "kernels/detail/number_text.hpp"
#include "kernels/detail/radix_sort.hpp"

namespace orthoflow::kernels {

std::string VoxelGridError::to_string() const {
  switch (code) {
    case Code::INVALID_LEAF:
      return "voxel_grid: invalid leaf size " + detail::value_text(value) +
             " (must be finite and > 0)";
    case Code::INDEX_OVERFLOW:
      return "voxel_grid: leaf too small for the extent, coordinate/leaf " +
             detail::value_text(value) + " does not fit a 64-bit voxel index";
    case Code::SCRATCH_TOO_SMALL:
      return "voxel_grid: scratch too small for " + detail::count_text(value) + " points";
    case Code::OUTPUT_TOO_SMALL:
      return "voxel_grid: output too small for " + detail::count_text(value) + " voxels";
  }
  return "voxel_grid: unknown error";
}

namespace {

constexpr float INDEX_LIMIT = 4.6e18F;  // below 2^62: differences of two indices still fit int64

bool finite3(float x, float y, float z) noexcept {
  return std::isfinite(x) && std::isfinite(y) && std::isfinite(z);
}

std::int64_t voxel_index(float coordinate, float inv_leaf) noexcept {
  // PCL: floor(p * inverse_leaf) in float, so that both give the same voxel set. Truncation then a
  // step down for negative non-integers is floor() exactly for |t| < 2^62 (checked by the caller on
  // the bounding box) and avoids a libm call per coordinate on the SSE2 baseline.
  const float t = coordinate * inv_leaf;
  const auto i = static_cast<std::int64_t>(t);
  return static_cast<float>(i) > t ? i - 1 : i;
}

/// Writes the centroid of every run of equal voxels in the sorted order. same(p, q) tells whether
/// the points at sorted positions p and q share a voxel.
template <class Same>
Result<std::size_t, VoxelGridError> emit_centroids(PointsView in, const std::uint32_t* order,
                                                   std::size_t n, Same same,
                                                   PointsSpan out) noexcept {
  std::size_t written = 0;
  for (std::size_t begin = 0; begin < n;) {
    std::size_t end = begin + 1;
    while (end < n && same(begin, end)) { ++end; }
    if (written >= out.size()) {
      return err(VoxelGridError{VoxelGridError::Code::OUTPUT_TOO_SMALL, double(n)});
    }
    double sx = 0.0, sy = 0.0, sz = 0.0;
    for (std::size_t k = begin; k < end; ++k) {
      sx += in.x[order[k]];
      sy += in.y[order[k]];
      sz += in.z[order[k]];
    }
    const double count = static_cast<double>(end - begin);
    out.x[written] = static_cast<float>(sx / count);
    out.y[written] = static_cast<float>(sy / count);
    out.z[written] = static_cast<float>(sz / count);
    ++written;
    begin = end;
  }
  return written;
}

/// Every sane grid: packed key ix + nx * (iy + ny * iz) relative to the lowest voxel, radix sorted.
Result<std::size_t, VoxelGridError> packed_path(PointsView in, float inv,
                                                const std::array<std::int64_t, 3>& lo,
                                                const std::array<std::int64_t, 3>& extent,
                                                std::uint64_t max_key, VoxelGridScratch& scratch,
                                                PointsSpan out) noexcept {
  const auto nx = static_cast<std::uint64_t>(extent[0]);
  const auto ny = static_cast<std::uint64_t>(extent[1]);
  std::size_t n = 0;
  for (std::size_t i = 0; i < in.size(); ++i) {
    if (!finite3(in.x[i], in.y[i], in.z[i])) { continue; }
    const auto ix = static_cast<std::uint64_t>(voxel_index(in.x[i], inv) - lo[0]);
    const auto iy = static_cast<std::uint64_t>(voxel_index(in.y[i], inv) - lo[1]);
    const auto iz = static_cast<std::uint64_t>(voxel_index(in.z[i], inv) - lo[2]);
    scratch.keys[n] = ix + nx * (iy + ny * iz);
    scratch.order[n++] = static_cast<std::uint32_t>(i);
  }
  const bool in_tmp =
      detail::radix_sort_pairs(scratch.keys.data(), scratch.keys_tmp.data(), scratch.order.data(),
                               scratch.order_tmp.data(), n, max_key);
  const std::uint64_t* keys = in_tmp ? scratch.keys_tmp.data() : scratch.keys.data();
  const std::uint32_t* order = in_tmp ? scratch.order_tmp.data() : scratch.order.data();
  return emit_centroids(
      in, order, n, [keys](std::size_t p, std::size_t q) { return keys[p] == keys[q]; }, out);
}

/// Grids of more than 2^64 cells (tiny leaf over a huge extent): sort by (iz, iy, ix), ties by
/// index.
Result<std::size_t, VoxelGridError> lexicographic_path(PointsView in, float inv,
                                                       VoxelGridScratch& scratch,
                                                       PointsSpan out) noexcept {
  std::size_t n = 0;
  for (std::size_t i = 0; i < in.size(); ++i) {
    if (finite3(in.x[i], in.y[i], in.z[i])) { scratch.order[n++] = static_cast<std::uint32_t>(i); }
  }
  auto triple = [&](std::uint32_t i) {
    return std::array<std::int64_t, 3>{voxel_index(in.z[i], inv), voxel_index(in.y[i], inv),
                                       voxel_index(in.x[i], inv)};
  };
  std::uint32_t* order = scratch.order.data();
  std::sort(order, order + n, [&](std::uint32_t a, std::uint32_t b) {
    const auto ta = triple(a);
    const auto tb = triple(b);
    return ta != tb ? ta < tb : a < b;
  });
  return emit_centroids(
      in, order, n,
      [&](std::size_t p, std::size_t q) { return triple(order[p]) == triple(order[q]); }, out);
}

}  // namespace

Result<std::size_t, VoxelGridError> voxel_grid(PointsView in, float leaf, VoxelGridScratch& scratch,
                                               PointsSpan out) noexcept {
  using Code = VoxelGridError::Code;
  const float inv = 1.0F / leaf;
  if (!std::isfinite(leaf) || !(leaf > 0.0F) || !std::isfinite(inv)) {
    return err(VoxelGridError{Code::INVALID_LEAF, leaf});
  }
  if (in.size() > scratch.capacity()) {
    return err(VoxelGridError{Code::SCRATCH_TOO_SMALL, double(in.size())});
  }
  const CloudStats stats = cloud_stats(in);
  if (stats.finite == 0) { return std::size_t{0}; }
  std::array<std::int64_t, 3> lo{}, extent{};
  for (std::size_t a = 0; a < 3; ++a) {
    for (const float bound : {stats.min[a], stats.max[a]}) {
      if (!(std::fabs(bound * inv) < INDEX_LIMIT)) {
        return err(VoxelGridError{Code::INDEX_OVERFLOW, bound * inv});
      }
    }
    lo[a] = voxel_index(stats.min[a], inv);
    extent[a] = voxel_index(stats.max[a], inv) - lo[a] + 1;
  }
  const unsigned __int128 cells = static_cast<unsigned __int128>(extent[0]) *
                                  static_cast<unsigned __int128>(extent[1]) *
                                  static_cast<unsigned __int128>(extent[2]);
  if (cells <= std::numeric_limits<std::uint64_t>::max()) {
    return packed_path(in, inv, lo, extent, static_cast<std::uint64_t>(cells - 1), scratch, out);
  }
  return lexicographic_path(in, inv, scratch, out);
}

}  // namespace orthoflow::kernels
