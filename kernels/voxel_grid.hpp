#pragma once
/// @file
/// @brief Voxel-grid downsampling: one output point per occupied voxel, the centroid of its points
/// (PCL VoxelGrid semantics: voxel index floor(coordinate * (1/leaf)) in float, NaN/Inf skipped).
/// Works at any extent and leaf: 64-bit packed voxel keys with a radix sort, and a lexicographic
/// (ix, iy, iz) sort when even 64 bits cannot hold the grid; an invalid leaf is an error.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/result.hpp"
#include "kernels/point_cloud.hpp"

namespace orthoflow::kernels {

/// @brief Why voxel_grid() refused to run; to_string() says what and with which value.
struct VoxelGridError {
  enum class Code : std::uint8_t {
    INVALID_LEAF,       ///< leaf not finite or <= 0
    INDEX_OVERFLOW,     ///< coordinate / leaf beyond +-2^62: the voxel index does not fit in int64
    SCRATCH_TOO_SMALL,  ///< the scratch holds fewer entries than the input has points
    OUTPUT_TOO_SMALL,   ///< more occupied voxels than the output holds
  };
  Code code = Code::INVALID_LEAF;
  double value = 0.0;  ///< the offending leaf, coordinate or size
  [[nodiscard]] std::string to_string() const;
};

/// @brief Working memory of voxel_grid(), sized once for the largest input (4 arrays of
/// max_points).
/// @note Allocates only in the constructor; reuse it frame after frame (not concurrently).
struct VoxelGridScratch {
  explicit VoxelGridScratch(std::size_t max_points)
      : keys(max_points), keys_tmp(max_points), order(max_points), order_tmp(max_points) {}
  std::vector<std::uint64_t> keys, keys_tmp;
  std::vector<std::uint32_t> order, order_tmp;
  [[nodiscard]] std::size_t capacity() const noexcept { return order.size(); }
};

/// @brief Downsamples @p in to the centroids of its occupied voxels of side @p leaf, written to
/// @p out in increasing voxel order (z slowest, then y, then x): deterministic for a given input.
/// Centroids are averaged in double then rounded to float.
/// @pre in.size() <= scratch.capacity() <= UINT32_MAX. @return the number of voxels written, or an
/// error (nothing useful written). @note Allocation-free; thread-safe with distinct scratch/output.
[[nodiscard]] Result<std::size_t, VoxelGridError> voxel_grid(PointsView in, float leaf,
                                                             VoxelGridScratch& scratch,
                                                             PointsSpan out) noexcept;

}  // namespace orthoflow::kernels
