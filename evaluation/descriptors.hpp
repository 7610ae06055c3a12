#pragma once
/// @file
/// @brief GOOD descriptors of every view of a dataset, with an optional perturbation of the view
/// first (thesis section 6.4.3: Gaussian noise, voxel downsampling), computed in parallel and
/// cached on disk.
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "evaluation/dataset.hpp"
#include "kernels/descriptor_spec.hpp"
#include "kernels/point_cloud.hpp"

namespace orthoflow::evaluation {

class Progress;

/// @brief What is done to a view before it is described.
enum class Perturbation : std::uint8_t {
  NONE,
  NOISE,       ///< zero-mean Gaussian noise of standard deviation `amount_m` added to x, y and z
  DOWNSAMPLE,  ///< voxel-grid centroids with leaf `amount_m` (kernels::voxel_grid)
};

/// @brief How a dataset view is described: the descriptor specification and what is done to the
/// view first (with the file's identity, the cache key).
struct ViewDescription {
  kernels::DescriptorSpec descriptor{};  ///< the representation (kind, parameters, length)
  Perturbation perturbation = Perturbation::NONE;
  double amount_m = 0.0;   ///< noise sigma or voxel leaf, metres (ignored for NONE)
  std::uint64_t seed = 0;  ///< noise draws (with the view's relative path); ignored otherwise
  /// @brief A file-name-safe key, e.g. "good-invariant-15-noise-5000um-s7".
  [[nodiscard]] std::string key() const;
  [[nodiscard]] std::size_t length() const noexcept { return descriptor.length(); }
};

/// @brief One descriptor per dataset view, row-major (row v = view v).
struct DescriptorTable {
  std::size_t length = 0;
  std::vector<float> values;
  [[nodiscard]] std::size_t size() const noexcept {
    return length == 0 ? 0 : values.size() / length;
  }
  [[nodiscard]] std::span<const float> row(std::size_t v) const noexcept {
    return std::span<const float>(values).subspan(v * length, length);
  }
};

/// @brief How a describe_dataset() call got its descriptors.
struct DescribeStats {
  std::size_t computed = 0;  ///< read, perturbed and described now
  std::size_t cached = 0;    ///< taken from the cache (file size and modification time unchanged)
};

/// @brief Applies @p spec's perturbation to the finite points of @p cloud, into @p out (x, y, z
/// only). Noise draws come from a generator seeded by (spec.seed, @p view_key), so a view gets the
/// same noise in every run, on every thread count and machine. @return false when the voxel grid
/// refuses the leaf.
[[nodiscard]] bool perturb_view(const kernels::PointCloud& cloud, const ViewDescription& spec,
                                std::string_view view_key, kernels::PointCloud& out);

/// @brief Describes every view of @p dataset under @p spec, in parallel (oneTBB; each view
/// independent, so the table is the same for any thread count). With a non-empty @p cache_dir,
/// descriptors of unchanged files are read from, and new ones written to,
/// `<cache_dir>/<spec.key()>-<dataset hash>.ofdc`. Errors: BAD_VIEW naming the first failing file
/// (unreadable PCD, no finite point, ...), BAD_CONFIG for bins outside 1..GOOD_MAX_BINS or a
/// negative or non-finite amount. A cache that cannot be read is ignored (recomputed); one that
/// cannot be written is reported on @p warnings and otherwise ignored.
[[nodiscard]] Result<DescriptorTable, EvalError> describe_dataset(
    const Dataset& dataset, const ViewDescription& spec, const std::filesystem::path& cache_dir,
    Progress* progress, DescribeStats* stats, std::vector<std::string>* warnings);

}  // namespace orthoflow::evaluation
