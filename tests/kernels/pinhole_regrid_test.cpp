// kernels/pinhole_regrid.hpp: an unorganized camera-frame cloud goes back on its pixel grid, every
// point on its own pixel; anything that is not such a cloud is refused with the reason.
#include "kernels/pinhole_regrid.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "formats/pcd_io.hpp"
#include "tests/support/unorganized_copy.hpp"

namespace orthoflow::kernels {
namespace {

constexpr float NaN = std::numeric_limits<float>::quiet_NaN();

/// A width x height pinhole image (fx, fy, cx, cy) of random depths with a share of NaN holes.
PointCloud pinhole_image(std::uint32_t width, std::uint32_t height, double fx, double fy, double cx,
                         double cy, double holes, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> depth(0.5F, 2.5F);
  std::bernoulli_distribution hole(holes);
  PointCloud c;
  c.add_field(Field::LABEL);
  c.resize(width, height);
  for (std::uint32_t v = 0; v < height; ++v) {
    for (std::uint32_t u = 0; u < width; ++u) {
      const std::size_t i = std::size_t{v} * width + u;
      c.label()[i] = static_cast<std::uint32_t>(i);
      if (hole(rng)) {
        c.x()[i] = c.y()[i] = c.z()[i] = NaN;
        continue;
      }
      const float z = depth(rng);
      c.x()[i] = static_cast<float>((u - cx) / fx) * z;
      c.y()[i] = static_cast<float>((v - cy) / fy) * z;
      c.z()[i] = z;
    }
  }
  return c;
}

/// Every valid pixel of @p original is in @p regridded at one common offset, bit for bit, and
/// nothing else is.
void expect_same_pixels(const PointCloud& original, const PointCloud& regridded) {
  ASSERT_TRUE(regridded.organized());
  ASSERT_LE(regridded.width(), original.width());
  ASSERT_LE(regridded.height(), original.height());
  // The offset: the first valid pixel of each.
  std::size_t first_o = 0, first_r = 0;
  while (!std::isfinite(original.z()[first_o])) ++first_o;
  std::size_t valid_r = 0;
  for (std::size_t i = 0; i < regridded.size(); ++i)
    valid_r += std::isfinite(regridded.z()[i]) ? 1U : 0U;
  while (!std::isfinite(regridded.z()[first_r])) ++first_r;
  const std::int64_t du = static_cast<std::int64_t>(first_o % original.width()) -
                          static_cast<std::int64_t>(first_r % regridded.width());
  const std::int64_t dv = static_cast<std::int64_t>(first_o / original.width()) -
                          static_cast<std::int64_t>(first_r / regridded.width());
  std::size_t valid_o = 0;
  for (std::size_t i = 0; i < original.size(); ++i) {
    if (!std::isfinite(original.z()[i])) continue;
    ++valid_o;
    const std::int64_t u = static_cast<std::int64_t>(i % original.width()) - du;
    const std::int64_t v = static_cast<std::int64_t>(i / original.width()) - dv;
    ASSERT_TRUE(u >= 0 && v >= 0 && u < regridded.width() && v < regridded.height()) << i;
    const std::size_t j =
        static_cast<std::size_t>(v) * regridded.width() + static_cast<std::size_t>(u);
    ASSERT_EQ(regridded.x()[j], original.x()[i]) << i;
    ASSERT_EQ(regridded.y()[j], original.y()[i]) << i;
    ASSERT_EQ(regridded.z()[j], original.z()[i]) << i;
    if (original.has(Field::LABEL)) { ASSERT_EQ(regridded.label()[j], original.label()[i]) << i; }
  }
  EXPECT_EQ(valid_r, valid_o);
}

/// Why find_pinhole_grid refused, or "accepted".
std::string_view refusal(const Result<PinholeGrid, GridRefusal>& r) {
  return r ? "accepted" : to_string(r.error());
}

TEST(PinholeRegrid, PutsTheMosdFramesBackOnTheirPixels) {
  for (const char* name : {"learn0", "learn21", "learn40"}) {
    auto organized =
        formats::read_pcd(std::string(ORTHOFLOW_SHARED_DIR) + "/data/mosd_learn/" + name + ".pcd");
    ASSERT_TRUE(organized) << name;
    PointCloud flat = test::unorganized_copy(*organized);
    auto grid = find_pinhole_grid(flat.points());
    ASSERT_TRUE(grid) << name << ": " << to_string(grid.error());
    EXPECT_LT(grid->max_residual_px, 0.01) << name;
    EXPECT_GT(grid->fx, 400.0);  // a Kinect v1's depth camera: about 525-595 px
    EXPECT_LT(grid->fx, 700.0);
    PointCloud regridded;
    regrid(flat, *grid, regridded);
    expect_same_pixels(*organized, regridded);
  }
}

TEST(PinholeRegrid, SyntheticGridsOfManyShapesAndHoleShares) {
  std::uint32_t seed = 1;
  for (const double holes : {0.0, 0.3, 0.7}) {
    for (const auto& [w, h] : {std::pair{64U, 48U}, std::pair{320U, 240U}, std::pair{33U, 97U}}) {
      const PointCloud original = pinhole_image(w, h, 525.3, 519.8, 31.7, 23.2, holes, seed++);
      PointCloud cloud = test::unorganized_copy(original);
      auto grid = organize_if_pinhole(cloud);
      if (cloud.size() < MIN_GRID_POINTS) {  // 64x48 with 70 % holes
        EXPECT_EQ(refusal(grid), to_string(GridRefusal::TOO_FEW_POINTS));
        continue;
      }
      ASSERT_TRUE(grid) << w << "x" << h << " holes " << holes << ": " << to_string(grid.error());
      EXPECT_NEAR(grid->fx, 525.3, 0.05);
      EXPECT_NEAR(grid->fy, 519.8, 0.05);
      expect_same_pixels(original, cloud);
    }
  }
}

TEST(PinholeRegrid, RefusesWhatIsNotAPinholeImage) {
  const PointCloud original = pinhole_image(160, 120, 525.0, 525.0, 80.0, 60.0, 0.2, 9);
  const PointCloud flat = test::unorganized_copy(original);
  // Empty, too few points, NaN / Inf / behind the sensor.
  EXPECT_EQ(refusal(find_pinhole_grid(PointsView{})), to_string(GridRefusal::TOO_FEW_POINTS));
  {
    PointCloud few = flat;
    few.resize_unorganized(MIN_GRID_POINTS - 1);
    EXPECT_EQ(refusal(find_pinhole_grid(few.points())), to_string(GridRefusal::TOO_FEW_POINTS));
    few = flat;
    for (std::size_t i = 0; i + MIN_GRID_POINTS - 1 < few.size(); ++i) few.z()[i] = -1.0F;
    EXPECT_EQ(refusal(find_pinhole_grid(few.points())), to_string(GridRefusal::TOO_FEW_POINTS));
  }
  {  // moved out of the camera frame: rotated 5 degrees about y
    PointCloud moved = flat;
    const float c = std::cos(0.087F), s = std::sin(0.087F);
    for (std::size_t i = 0; i < moved.size(); ++i) {
      const float x = moved.x()[i], z = moved.z()[i];
      moved.x()[i] = c * x + s * z;
      moved.z()[i] = -s * x + c * z;
    }
    auto grid = find_pinhole_grid(
        moved.points());  // its rows are no longer rows: no pitch, or points off the grid
    EXPECT_TRUE(refusal(grid) == to_string(GridRefusal::NO_PITCH) ||
                refusal(grid) == to_string(GridRefusal::OFF_GRID))
        << refusal(grid);
  }
  {  // shuffled: the stored order says nothing about rows
    PointCloud shuffled = flat;
    std::mt19937 rng(3);
    for (std::size_t i = shuffled.size() - 1; i > 0; --i) {
      const std::size_t j = std::uniform_int_distribution<std::size_t>(0, i)(rng);
      std::swap(shuffled.x()[i], shuffled.x()[j]);
      std::swap(shuffled.y()[i], shuffled.y()[j]);
      std::swap(shuffled.z()[i], shuffled.z()[j]);
    }
    EXPECT_EQ(refusal(find_pinhole_grid(shuffled.points())), to_string(GridRefusal::NO_PITCH));
  }
  {  // two points on one pixel (the same ray at another depth)
    PointCloud doubled = flat;
    doubled.resize_unorganized(flat.size() + 1);
    doubled.x().back() = flat.x()[500] * 1.5F;
    doubled.y().back() = flat.y()[500] * 1.5F;
    doubled.z().back() = flat.z()[500] * 1.5F;
    EXPECT_EQ(refusal(find_pinhole_grid(doubled.points())), to_string(GridRefusal::SHARED_PIXEL));
  }
  {  // one point half a pixel off
    PointCloud off = flat;
    off.x()[700] += 0.5F / 525.0F * off.z()[700];
    EXPECT_EQ(refusal(find_pinhole_grid(off.points())), to_string(GridRefusal::OFF_GRID));
  }
  // An organized cloud is left as it is.
  PointCloud organized = original;
  auto same = organize_if_pinhole(organized);
  ASSERT_TRUE(same);
  EXPECT_EQ(organized.width(), 160U);
  EXPECT_EQ(organized.height(), 120U);
}

}  // namespace
}  // namespace orthoflow::kernels
