#pragma once
/// @file
/// @brief Kinect v1 colour camera: bilinear demosaic of the 8-bit GRBG Bayer mosaic
/// (specs/KINECT_V1.md section 7.3) to RGB24 or to the point clouds' packed colour, and the
/// inverse sampling for simulators and tests.
///
/// GRBG: row 0 is G R G R ..., row 1 is B G B G ..., so pixel (y, x) holds G when y and x have
/// the same parity, R when y is even and x odd, B when y is odd and x even.
///
/// Interior pixels: each missing colour is the rounded integer mean of the nearest samples of that
/// colour: (a + b + 1) / 2 for two (G pixels: R and B from the row or column neighbours),
/// (a + b + c + d + 2) / 4 for four (G at R/B pixels from the 4 edge neighbours, B at R pixels and
/// R at B pixels from the 4 diagonal neighbours).
///
/// Border rule (first/last row and column): a neighbour index that falls outside the image is
/// reflected about the border pixel, without repeating it: row -1 reads row 1, row height reads
/// row height - 2, column -1 reads column 1, column width reads column width - 2 (reflect-101).
/// The reflected sample has the colour the missing one would have had, and the interior formula
/// is then applied unchanged. In terms of the samples that exist, this gives:
/// - two-sample means with one side missing: the one existing sample;
/// - four edge neighbours with one missing (a non-corner R/B pixel on the border): the opposite
///   neighbour counts twice, (2a + b + c + 2) / 4; with two missing (a corner): (2a + 2b + 2) / 4,
///   which equals (a + b + 1) / 2;
/// - four diagonals with two missing (border, not corner): (2a + 2b + 2) / 4 = (a + b + 1) / 2;
///   with three missing (corner): the one existing diagonal.
/// With width or height 2 both reflections read the same row/column, so e.g. a 2x2 image gives
/// every pixel the one R, the one B and (for R/B pixels) the mean of the two G samples.
///
/// Integer arithmetic only: every variant (scalar, SSE2, AVX2, AVX-512BW, NEON) gives the same
/// bytes.
#include <cstddef>
#include <cstdint>
#include <span>

namespace orthoflow::kernels {

/// @brief Alpha byte of demosaic_grbg_packed()'s output, as the point clouds store colour
/// (PointCloud::rgb() is 0xAARRGGBB; the simulator and the PLY reader write alpha 255).
inline constexpr std::uint32_t DEMOSAIC_ALPHA = 0xFF000000U;

/// @brief Bilinear demosaic of a GRBG mosaic: @p rgb is width*height packed RGB24 (R, G, B bytes
/// per pixel, rows top to bottom). Missing colours and borders as in the file comment.
/// @pre width and height are even and >= 2; bayer.size() == width*height; rgb.size() ==
/// 3*width*height (OF_ASSERT).
/// @note Stateless and thread-safe. Reads only @p bayer and writes only @p rgb. Equal to
/// demosaic_grbg_scalar() bit for bit on every architecture.
void demosaic_grbg(std::span<const std::uint8_t> bayer, std::uint32_t width, std::uint32_t height,
                   std::span<std::uint8_t> rgb) noexcept;
/// @brief Scalar reference twin of demosaic_grbg(). @pre as demosaic_grbg().
void demosaic_grbg_scalar(std::span<const std::uint8_t> bayer, std::uint32_t width,
                          std::uint32_t height, std::span<std::uint8_t> rgb) noexcept;

/// @brief As demosaic_grbg(), written as the point clouds' packed colour: pixel i is
/// DEMOSAIC_ALPHA | R << 16 | G << 8 | B (0xFFRRGGBB, PointCloud::rgb()'s layout).
/// @pre width and height are even and >= 2; bayer.size() == width*height; rgb.size() ==
/// width*height (OF_ASSERT).
/// @note Stateless and thread-safe. Equal to demosaic_grbg_packed_scalar() bit for bit, and to
/// demosaic_grbg()'s RGB24 repacked.
void demosaic_grbg_packed(std::span<const std::uint8_t> bayer, std::uint32_t width,
                          std::uint32_t height, std::span<std::uint32_t> rgb) noexcept;
/// @brief Scalar reference twin of demosaic_grbg_packed(). @pre as demosaic_grbg_packed().
void demosaic_grbg_packed_scalar(std::span<const std::uint8_t> bayer, std::uint32_t width,
                                 std::uint32_t height, std::span<std::uint32_t> rgb) noexcept;

/// @brief The inverse, for simulators and tests: samples the RGB24 image @p rgb into a GRBG
/// mosaic (pixel (y, x) keeps its G byte when y and x have the same parity, its R byte when y is
/// even and x odd, its B byte when y is odd and x even).
/// @pre width and height are even and >= 2; rgb.size() == 3*width*height; bayer.size() ==
/// width*height (OF_ASSERT).
/// @note Stateless and thread-safe. A flat colour survives mosaic_grbg() then demosaic_grbg().
void mosaic_grbg(std::span<const std::uint8_t> rgb, std::uint32_t width, std::uint32_t height,
                 std::span<std::uint8_t> bayer) noexcept;

}  // namespace orthoflow::kernels
