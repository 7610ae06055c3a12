#pragma once
/// @file
/// @brief The dictionary builder (thesis chapters 3 and 4): k-means over a pool of spin images from
/// an exploration stage, the cluster centres being the visual words of the bag of words
/// (kernels/visual_words.hpp); and the dictionary's file, which a perceptual memory, `describe` and
/// `evaluate` read.
///
/// k-means is seeded (k-means++ initialisation, core::Rng) and exact: every distance in double
/// precision in dimension order, points assigned in parallel (oneTBB) but each independently, the
/// centres summed in point order. The same pool and seed give the same words bit for bit on any
/// thread count, and on x86 and ARM.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "core/result.hpp"
#include "kernels/spin_features.hpp"
#include "kernels/visual_words.hpp"

namespace orthoflow::learning {

struct KMeansParams {
  std::size_t k = 70;                  ///< clusters (the thesis's dictionary size DS: 70)
  std::uint32_t max_iterations = 100;  ///< Lloyd iterations at most
  std::uint64_t seed = 1;
};

struct KMeansResult {
  std::vector<float> centres;             ///< k rows of dims values (row-major)
  std::vector<std::uint32_t> assignment;  ///< the centre of each row of the pool
  double inertia = 0.0;                   ///< sum of squared distances to the assigned centres
  std::uint32_t iterations = 0;  ///< Lloyd iterations run (stops when no assignment changes)
};

/// @brief k-means of @p rows (count x dims, row-major). Refuses, with the reason, k = 0, dims = 0,
/// fewer rows than k, or a value that is not finite. A cluster left empty takes the row farthest
/// from its centre (lowest index on ties).
[[nodiscard]] Result<KMeansResult, std::string> kmeans(std::span<const float> rows,
                                                       std::size_t dims,
                                                       const KMeansParams& params);

/// @brief A dictionary of @p params.k words from @p pool (spin images made with @p features,
/// rows with no weight left out first). @p provenance says where the pool came from.
[[nodiscard]] Result<kernels::VisualDictionary, std::string> build_dictionary(
    std::span<const float> pool, const kernels::SpinFeatureParams& features,
    const KMeansParams& params, std::string provenance);

/// @brief The file bytes of @p d (magic "OFWD", version 1, little-endian).
[[nodiscard]] std::string encode_dictionary(const kernels::VisualDictionary& d);
/// @brief Parses a dictionary file's bytes; every field bounds-checked, the id recomputed and
/// compared with the stored one (fuzzed by tests/fuzz). @return the dictionary or why not.
[[nodiscard]] Result<kernels::VisualDictionary, std::string> parse_dictionary(
    std::span<const char> bytes);
/// @brief Writes @p d through a temporary file and a rename. @return an error sentence or "".
[[nodiscard]] std::string save_dictionary(const kernels::VisualDictionary& d,
                                          const std::filesystem::path& path);
/// @brief Reads and parses a dictionary file; errors name the file.
[[nodiscard]] Result<kernels::VisualDictionary, std::string> load_dictionary(
    const std::filesystem::path& path);

}  // namespace orthoflow::learning
