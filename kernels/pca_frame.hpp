#pragma once
/// @file
/// @brief Principal-axes frame of a point cloud (PIPELINE.md section 6): centroid, covariance
/// C = (1/m) sum (p - c)(p - c)^T, eigenvalues sorted descending, eigenvectors, and flags saying
/// when the axes are not well defined. Sign disambiguation is done by compute_good()
/// (kernels/good.hpp).
#include <array>
#include <cstddef>
#include <cstdint>

#include "core/result.hpp"
#include "kernels/point_cloud.hpp"

namespace orthoflow::kernels {

/// @brief Bits of PcaFrame::flags and GoodResult::flags. Any bit of FRAME_UNRELIABLE means the
/// frame (and therefore a pose-invariant descriptor) may change with the pose or with tiny
/// perturbations.
enum FrameFlag : std::uint32_t {
  FEW_POINTS = 1U << 0,  ///< fewer than 3 finite points
  COLLINEAR = 1U << 1,   ///< lambda2 <= 1e-6 lambda1 (includes identical points, lambda1 == 0)
  COPLANAR =
      1U << 2,  ///< lambda3 <= 1e-6 lambda1: the normal is defined, the in-plane axes may not be
  AXES_AMBIGUOUS = 1U << 3,  ///< a relative eigenvalue gap (l1-l2)/l1 or (l2-l3)/l1 is below 5 %
  SIGN_AMBIGUOUS = 1U << 4,  ///< an axis sign fell through every rule of the invariant tie chain
  NAN_IGNORED = 1U << 5,     ///< some points had a non-finite coordinate and were skipped
  EMPTY_VIEW = 1U << 6,      ///< a projection kept no point (only with extents that overflow float)
  FAR_POINTS_DROPPED = 1U << 7,  ///< far points were left out of the frame (kernels/far_points.hpp)
};
/// @brief The flags that make a frame unreliable (NAN_IGNORED, EMPTY_VIEW and FAR_POINTS_DROPPED
/// are informative).
inline constexpr std::uint32_t FRAME_UNRELIABLE =
    FEW_POINTS | COLLINEAR | COPLANAR | AXES_AMBIGUOUS | SIGN_AMBIGUOUS;

/// @brief Relative eigenvalue gap below which AXES_AMBIGUOUS is set.
inline constexpr double AXES_GAP_MIN = 0.05;
/// @brief Relative eigenvalue size below which COLLINEAR / COPLANAR are set.
inline constexpr double FLAT_RATIO = 1e-6;

/// @brief Principal axes of the finite points of a cloud.
struct PcaFrame {
  std::array<double, 3> centroid{};     ///< mean of the finite points
  std::array<double, 3> eigenvalues{};  ///< lambda1 >= lambda2 >= lambda3 >= 0 of the /m covariance
  /// @brief axes[k] is the unit eigenvector of eigenvalues[k]; axes[2] = axes[0] x axes[1]
  /// (right-handed). Their signs are whatever the eigen solver returns: deterministic for one
  /// input, arbitrary across poses.
  std::array<std::array<double, 3>, 3> axes{};
  std::size_t finite = 0;   ///< points used (x, y and z finite)
  std::uint32_t flags = 0;  ///< FrameFlag bits
};

/// @brief Sums over the finite points about @p origin (the first finite point): the covariance
/// input.
struct PcaMoments {
  std::array<double, 3> origin{};
  std::array<double, 3> sum{};  ///< sum of d = p - origin
  std::array<double, 6> sq{};   ///< sum of d d^T: xx xy xz yy yz zz
  std::size_t count = 0;        ///< finite points
};

/// @brief Moments in double (SIMD over double lanes, dispatched at run time).
/// @pre x, y and z have equal lengths. @note No allocation; thread-safe; deterministic on one
/// machine. Tolerance against pca_moments_scalar(): summation order differs by lane, so sums agree
/// to ~1e-15 relative.
[[nodiscard]] PcaMoments pca_moments(PointsView points) noexcept;
/// @brief Scalar reference twin of pca_moments(), in point order.
[[nodiscard]] PcaMoments pca_moments_scalar(PointsView points) noexcept;

/// @brief Why no frame could be computed.
enum class PcaError : std::uint8_t {
  EMPTY_CLOUD,       ///< the cloud has no points
  NO_FINITE_POINTS,  ///< every point has a NaN or infinite coordinate
};
/// @brief What the error means, as a sentence.
[[nodiscard]] const char* to_string(PcaError error) noexcept;

/// @brief Centroid, covariance (accumulated in double about the first finite point, which keeps
/// clouds far from the origin exact enough) and the eigen-decomposition (Eigen's
/// SelfAdjointEigenSolver on the double 3x3 matrix). Non-finite points are skipped and not counted.
/// @pre x, y and z have equal lengths.
/// @note No allocation; thread-safe; deterministic (same input, same output, bit for bit).
[[nodiscard]] Result<PcaFrame, PcaError> compute_pca_frame(PointsView points) noexcept;
/// @brief compute_pca_frame() with pca_moments_scalar().
[[nodiscard]] Result<PcaFrame, PcaError> compute_pca_frame_scalar(PointsView points) noexcept;
/// @brief The frame from moments of a cloud of @p total_points points (finite or not).
[[nodiscard]] Result<PcaFrame, PcaError> pca_frame_from_moments(const PcaMoments& m,
                                                                std::size_t total_points) noexcept;

}  // namespace orthoflow::kernels
