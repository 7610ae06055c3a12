#pragma once
/// @file
/// @brief Several partial views derived from one real view, for sanity checks on data that has a
/// single view per object (e.g. the four real restaurant views in shared/data/objects): each
/// derived view keeps the points on one side of a random plane through the cloud (a random 70-100 %
/// of them) and adds 1 mm Gaussian noise. It exercises the pipeline on real sensor data; it does
/// not measure generalisation to unseen objects (every derived view comes from the same physical
/// view).
#include <cstdint>

#include "kernels/point_cloud.hpp"

namespace orthoflow::evaluation {

/// @brief Derived view @p index of @p cloud (finite points only; x, y, z). Deterministic in
/// (@p seed, @p index); the first view (index 0) is the whole cloud without noise.
[[nodiscard]] kernels::PointCloud derive_view(const kernels::PointCloud& cloud, std::uint32_t index,
                                              std::uint64_t seed);

}  // namespace orthoflow::evaluation
