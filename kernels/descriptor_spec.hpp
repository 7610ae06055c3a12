#pragma once
/// @file
/// @brief One descriptor specification: the representation's kind, its parameters and its length
/// travel together as one value (STYLE rule 18). The describe node, the learners, the perceptual
/// memory, the evaluation and the CLI ask the specification for the length instead of computing one
/// of their own, and a store records the specification it was written with. GOOD is the one kind
/// today; the local-feature representations (spin-image sets, bag of words, topic models) are added
/// as kinds here.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "core/result.hpp"
#include "kernels/good.hpp"

namespace orthoflow::kernels {

/// @brief The representation a descriptor is.
enum class DescriptorKind : std::uint8_t {
  GOOD,  ///< the Global Orthographic Object Descriptor: 3 n^2 normalised histogram values
};
/// @brief "good".
[[nodiscard]] std::string_view to_string(DescriptorKind kind) noexcept;

/// @brief Kind, parameters and length of a descriptor. A plain value; compare with ==.
struct DescriptorSpec {
  DescriptorKind kind = DescriptorKind::GOOD;
  GoodConfig good{};  ///< kind GOOD: bins, frame rule and sign threshold (thesis: 15 bins)

  /// @brief A GOOD specification.
  [[nodiscard]] static DescriptorSpec make_good(std::size_t bins,
                                                GoodMode mode = GoodMode::INVARIANT) noexcept;
  /// @brief Values per descriptor (GOOD: 3 n^2).
  [[nodiscard]] std::size_t length() const noexcept;
  /// @brief Every value is a non-negative histogram share (what a naive Bayes learner needs).
  [[nodiscard]] bool histogram() const noexcept;
  /// @brief Checks the parameters (bins in 1..GOOD_MAX_BINS, a finite non-negative threshold).
  [[nodiscard]] Result<void, std::string> validate() const;
  /// @brief "good bins=15 mode=invariant threshold=0.015": what a mismatch error names.
  [[nodiscard]] std::string describe() const;
  /// @brief Same kind and parameters (GOOD: the effective threshold, so unset equals the mode's
  /// default).
  [[nodiscard]] bool operator==(const DescriptorSpec& other) const noexcept;
};

/// @brief Everything describing one object view reports besides the values.
struct DescriptorInfo {
  std::size_t length = 0;         ///< values written
  std::array<float, 16> frame{};  ///< world -> object transform, row-major (GoodResult::frame)
  std::array<float, 3> bbox{};    ///< object-frame box edges (GoodResult::bbox)
  std::uint32_t flags = 0;        ///< GoodResult::flags
};

/// @brief Describes object views under one specification; owns its scratch (sized once).
/// @note Not thread-safe: one describer per thread (or per concurrent object).
class Describer {
 public:
  /// @pre spec.validate() succeeded.
  explicit Describer(const DescriptorSpec& spec);
  [[nodiscard]] const DescriptorSpec& spec() const noexcept { return spec_; }
  /// @brief Writes the descriptor of @p points to the front of @p out. @pre out.size() >=
  /// spec().length(). Allocation-free. Deterministic (SIMD tolerance as compute_good()).
  [[nodiscard]] Result<DescriptorInfo, GoodError> describe(PointsView points,
                                                           std::span<float> out) noexcept;

 private:
  DescriptorSpec spec_;
  GoodScratch good_scratch_;
};

}  // namespace orthoflow::kernels
