#pragma once
/// @file
/// @brief Choosing the classification threshold CT of InstanceLearner from the stored views
/// (docs/LEARNING.md, "Choosing CT"). Leave-one-out: every stored view T of category C (with |C| >=
/// 2) is removed from C, its NOCD to the rest of C is a "known" sample (should be <= CT) and its
/// smallest NOCD to every other category is an "unknown" sample (as if C had never been taught:
/// should be > CT). CT is the midpoint between two consecutive sorted samples that maximises
/// balanced accuracy (mean of the known and unknown acceptance rates); ties keep the smallest CT.
#include <cstddef>
#include <span>

#include "learning/instance_learner.hpp"

namespace orthoflow::learning {

/// @brief The outcome of calibrate_threshold().
struct Calibration {
  float threshold = 0.0F;          ///< the CT to configure
  float balanced_accuracy = 0.0F;  ///< in [0.5, 1] on the leave-one-out samples
  std::size_t known_samples = 0;
  std::size_t unknown_samples = 0;
};

/// @brief Why no threshold was computed.
enum class CalibrationError : std::uint8_t {
  TOO_FEW_CATEGORIES,  ///< fewer than two categories: there is no "other category" sample
  TOO_FEW_VIEWS,       ///< no category has two or more views: there is no "known" sample
};
/// @brief A sentence saying what was missing.
[[nodiscard]] const char* to_string(CalibrationError error) noexcept;

/// @brief Leave-one-out CT for @p cfg (approach, normalisation, ICD rules) over @p categories.
/// @pre every category's views have cfg.descriptor_length values. @note Allocates (start-up/offline
/// tool, not the frame path): O(V^2) floats for the distance table and O(V^2 L) time for V views of
/// length L (2 000 views: 16 MB). Deterministic.
[[nodiscard]] Result<Calibration, CalibrationError> calibrate_threshold(
    std::span<const RestoredCategory> categories, const InstanceConfig& cfg);

}  // namespace orthoflow::learning
