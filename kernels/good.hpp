#pragma once
/// @file
/// @brief GOOD, the Global Orthographic Object Descriptor (PIPELINE.md section 6,
/// GOOD_REFERENCE.md): the object frame, three orthographic n x n projections, per-projection
/// normalisation, entropy and variance ordering. Two modes, one code path (docs/GOOD.md):
/// - INVARIANT (default): X = Sx v1, Y = Sy v2, Z = X x Y, each sign chosen on its own by the rule
/// in
///   docs/GOOD.md, so every rigid pose of one object gives the same descriptor. Default threshold
///   0.015 m (the thesis value).
/// - REFERENCE: the public reference implementation's frame rule: s = Sx * Sy with the floor(m/10)
/// count
///   margin, applied to x and y only. Default threshold 0.0015 m (the reference code's default).
/// Both modes keep the reference's binning: side L = largest AABB edge + 0.02 m, square centred on
/// the centroid, truncating bin index, points outside the square dropped, one view normalised by
/// its kept count.
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "core/result.hpp"
#include "kernels/pca_frame.hpp"
#include "kernels/point_cloud.hpp"

namespace orthoflow::kernels {

/// @brief How the signs of the principal axes are chosen.
enum class GoodMode : std::uint8_t { INVARIANT, REFERENCE };

/// @brief The three projections in canonical order (the reference's view index).
enum class GoodView : std::uint8_t { YOZ = 0, XOZ = 1, XOY = 2 };
/// @brief "YoZ", "XoZ" or "XoY".
[[nodiscard]] const char* to_string(GoodView view) noexcept;

/// @brief Default sign threshold of the invariant mode (thesis, PIPELINE.md section 6).
inline constexpr float GOOD_INVARIANT_THRESHOLD = 0.015F;
/// @brief Default sign threshold of the reference mode (the reference code's default,
/// GOOD_REFERENCE.md 0).
inline constexpr float GOOD_REFERENCE_THRESHOLD = 0.0015F;
/// @brief Fixed margin added to the largest bounding-box edge (GOOD_REFERENCE.md section 5).
inline constexpr float GOOD_SQUARE_MARGIN = 0.02F;
/// @brief Largest bin count accepted (3 n^2 values must stay small).
inline constexpr std::size_t GOOD_MAX_BINS = 256;

/// @brief Plain configuration, validated by compute_good().
struct GoodConfig {
  std::size_t bins = 15;  ///< n: bins per side, 1..GOOD_MAX_BINS (15 thesis, 5 compact)
  GoodMode mode = GoodMode::INVARIANT;  ///< frame rule
  std::optional<float> threshold;       ///< sign threshold t in metres; unset = the mode's default
  /// @brief The threshold in use: the set value, or the mode's default.
  [[nodiscard]] float effective_threshold() const noexcept {
    return threshold ? *threshold
                     : (mode == GoodMode::INVARIANT ? GOOD_INVARIANT_THRESHOLD
                                                    : GOOD_REFERENCE_THRESHOLD);
  }
};

/// @brief Everything compute_good() reports besides the descriptor.
struct GoodResult {
  std::size_t length = 0;  ///< values written to the descriptor: 3 n^2
  std::array<float, 16>
      frame{};  ///< world -> object transform, row-major; rows 0-2 are X, Y, Z; t = -R c
  std::array<float, 3> bbox{};      ///< AABB edge lengths along X, Y, Z of the object frame
  std::array<GoodView, 3> order{};  ///< the projection of each descriptor block, first block first
  std::array<std::size_t, 3> kept{};  ///< points binned per view, canonical order (YoZ, XoZ, XoY)
  std::array<float, 3> entropy{};     ///< base-2 entropy per view, canonical order
  std::array<float, 3>
      variance{};  ///< variance of the 1-based flattened bin index per view, canonical order
  std::array<float, 3> eigenvalues{};  ///< lambda1 >= lambda2 >= lambda3
  std::array<int, 3> signs{};          ///< signs applied to (v1, v2, v3) to get (X, Y, Z)
  float side = 0.0F;                   ///< square side L = largest edge + 0.02 m
  std::size_t points_used = 0;         ///< finite points the frame and the projections used
  std::size_t far_points = 0;          ///< finite points left out as far (kernels/far_points.hpp)
  std::uint32_t flags = 0;  ///< FrameFlag bits (FRAME_UNRELIABLE: do not trust invariance)
};

/// @brief Why no descriptor was computed.
enum class GoodError : std::uint8_t {
  EMPTY_CLOUD,        ///< the cloud has no points
  NO_FINITE_POINTS,   ///< every point has a NaN or infinite coordinate
  BAD_BINS,           ///< bins is 0 or above GOOD_MAX_BINS
  BAD_THRESHOLD,      ///< the threshold is negative or not finite
  OUTPUT_TOO_SMALL,   ///< descriptor_out holds fewer than 3 n^2 values
  SCRATCH_TOO_SMALL,  ///< the scratch was made for fewer bins than requested
  OUT_OF_MEMORY,      ///< the scratch could not grow to hold a view without its far points
  /// Describer, bag of words: the keypoints' voxel grid refused the view (too wide for its leaf).
  KEYPOINTS_FAILED,
  NO_FEATURES,  ///< Describer, bag of words: no spin image has weight (a view too small or sparse)
  TOO_MANY_POINTS,  ///< Describer, bag of words: a view larger than its fixed scratch holds
};
/// @brief What the error means, as a sentence naming compute_good and the offending value's role.
[[nodiscard]] const char* to_string(GoodError error) noexcept;

/// @brief Histogram memory for compute_good(), allocated once by the caller (not on the frame
/// path).
/// @note Not thread-safe: one scratch per thread.
class GoodScratch {
 public:
  /// @brief Room for up to @p max_bins bins per side.
  explicit GoodScratch(std::size_t max_bins = 15)
      : max_bins_(max_bins), counts_(3 * max_bins * max_bins + 3) {}
  [[nodiscard]] std::size_t max_bins() const noexcept { return max_bins_; }
  /// @brief Raw counts of @p view (row-major n x n) from the last compute_good() call with n bins.
  [[nodiscard]] std::span<const std::uint32_t> counts(GoodView view,
                                                      std::size_t bins) const noexcept {
    return std::span<const std::uint32_t>(counts_).subspan(
        static_cast<std::size_t>(view) * bins * bins, bins * bins);
  }
  /// @brief The whole buffer (3 n^2 counts in canonical order, then 3 drop counters); for
  /// compute_good() only.
  [[nodiscard]] std::span<std::uint32_t> buffer() noexcept { return counts_; }
  /// @brief Room for a copy of @p n points (a view without its far points); for compute_good()
  /// only. Grows (allocates) only when a view with far points is larger than any before it.
  /// @return the room, or an empty span when memory ran out.
  [[nodiscard]] PointsSpan near_points(std::size_t n) noexcept;

 private:
  std::size_t max_bins_;
  std::vector<std::uint32_t> counts_;
  std::vector<float> near_;  ///< x, y and z of near_points(), one third each
};

/// @brief Computes the GOOD descriptor of the finite points of @p points, far points left out
/// (kernels/far_points.hpp: a view without far points is described exactly as before; one with
/// them is described from a copy in the scratch, flagged FAR_POINTS_DROPPED).
/// The three n x n projection matrices are the three blocks of @p descriptor_out, in
/// GoodResult::order; each block is row-major (row = first named axis, column = second) and sums
/// to 1.
/// @pre x, y and z have equal lengths.
/// @note No allocation (but for a view with far points larger than any before, see
/// GoodScratch::near_points); thread-safe with one scratch per thread; deterministic on one
/// machine. Tolerance against compute_good_scalar(): the frame is identical (computed by the same
/// scalar code); the AVX2/AVX-512 units let the compiler fuse a*b+c into FMA, so a transformed
/// coordinate may differ by one rounding and a point lying within that of a bin edge or of +-t may
/// change side: the descriptor L1 difference is at most a few points / kept (tested <= 1e-3 on the
/// shared clouds). SSE2 is exact.
[[nodiscard]] Result<GoodResult, GoodError> compute_good(PointsView points, const GoodConfig& cfg,
                                                         GoodScratch& scratch,
                                                         std::span<float> descriptor_out) noexcept;
/// @brief Scalar reference twin of compute_good().
[[nodiscard]] Result<GoodResult, GoodError> compute_good_scalar(
    PointsView points, const GoodConfig& cfg, GoodScratch& scratch,
    std::span<float> descriptor_out) noexcept;

}  // namespace orthoflow::kernels
