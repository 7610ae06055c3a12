#pragma once
/// @file
/// @brief Seeded inputs and what the engine computes from them, as JSON, for the cross-architecture
/// determinism test: tests/golden/determinism.json holds the outputs of an x86-64 build
/// (`determinism_golden --out tests/golden/determinism.json` regenerates it), and determinism_test
/// recomputes them on the running architecture (x86-64 natively, aarch64 under qemu) and compares.
///
/// What must agree, and how closely (the tolerances below are what the test enforces):
/// - synthetic scenes: bit for bit (hashes of every field). The renderer uses only IEEE-exact
/// operations
///   plus libm at setup (drivers/README.md), so a mismatch is a real portability bug.
/// - segmentation chain on those scenes: FMA contraction (aarch64 GCC fuses a*b+c everywhere; the
/// x86
///   AVX2/AVX-512 units do too) moves a point lying within one rounding of the RANSAC threshold or
///   of a prism face across it, so plane coefficients, inlier and cluster sizes may differ
///   slightly; the object count must be equal.
/// - GOOD descriptors (15 bins) of the shared real views and of a synthetic object: L1 distance.
/// - learner decisions: the same label and unknown flag at every step, scores within a relative
/// tolerance.
#include <string>

#include <nlohmann/json.hpp>

namespace orthoflow::testing {

/// @brief Largest difference of a plane normal component or of d (metres) between architectures.
inline constexpr double GOLDEN_PLANE_TOL = 1e-4;
/// @brief Largest relative difference of the RANSAC inlier count.
inline constexpr double GOLDEN_INLIER_REL_TOL = 1e-3;
/// @brief Largest difference of one cluster's size, in points (sizes compared largest first).
inline constexpr long GOLDEN_CLUSTER_POINTS_TOL = 3;
/// @brief Largest L1 distance between a GOOD descriptor (sums to 3) and its golden value.
inline constexpr double GOLDEN_GOOD_L1_TOL = 2e-3;

/// @brief Largest relative difference of a learner's decision score (the descriptors may differ
/// within GOLDEN_GOOD_L1_TOL, and the distance kernels agree within 1e-5 relative across SIMD
/// widths).
inline constexpr double GOLDEN_SCORE_REL_TOL = 1e-3;

/// @brief Seeds of the synthetic scenes (6 objects each, as `orthoflow synth --seed S`).
inline constexpr unsigned long long GOLDEN_SCENE_SEEDS[] = {3, 11};

/// @brief FNV-1a 64 of each field of each synthetic scene, plus its size and finite point count.
/// @note Deterministic; allocates (test code, not the frame path).
[[nodiscard]] nlohmann::json golden_scenes();
/// @brief The segmentation chain (default parameters) on each synthetic scene: plane, inliers,
/// cluster sizes.
[[nodiscard]] nlohmann::json golden_segmentation();
/// @brief GOOD descriptors (15 bins, invariant mode) of every view in @p shared_dir/data/objects
/// and of a rendered synthetic mug; throws std::runtime_error naming the file when a view cannot be
/// read.
[[nodiscard]] nlohmann::json golden_good(const std::string& shared_dir);
/// @brief A fixed open-ended sequence on InstanceLearner and BayesLearner (defaults): 4 categories
/// taught one by one (2 instances x 2 rendered views each), and after each, the decision on 8
/// held-out views.
[[nodiscard]] nlohmann::json golden_learning();
/// @brief Every section above, plus "generated_on" (the dispatched SIMD architecture).
[[nodiscard]] nlohmann::json golden_all(const std::string& shared_dir);

}  // namespace orthoflow::testing
