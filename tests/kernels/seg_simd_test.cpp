// Every compiled SIMD variant of the segmentation kernels against its scalar twin, on random and
// adversarial inputs: empty, all-NaN, one point, sizes around the lane counts 4/8/16, huge
// coordinates, duplicates. Exact kernels must be equal; FMA-sensitive ones within the header
// tolerance.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "kernels/detail/crop_kernel.hpp"
#include "kernels/detail/depth_projection_kernel.hpp"
#include "kernels/detail/plane_distance_kernel.hpp"
#include "kernels/polygonal_prism.hpp"

namespace ok = orthoflow::kernels;

namespace {

constexpr float NAN_F = std::numeric_limits<float>::quiet_NaN();

struct Cloud {
  std::vector<float> x, y, z;
  ok::PointsView view() const { return {x, y, z}; }
};

enum class Kind { RANDOM, ALL_NAN, HUGE, DUPLICATES };

Cloud make_cloud(std::size_t n, Kind kind, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> coord(-1.5F, 1.5F);
  std::uniform_real_distribution<float> unit(0.0F, 1.0F);
  Cloud c;
  for (std::size_t i = 0; i < n; ++i) {
    float p[3] = {coord(rng), coord(rng), coord(rng)};
    if (kind == Kind::HUGE) {
      for (float& v : p) { v *= 1e30F; }
    }
    if (kind == Kind::DUPLICATES && i > 0) { p[0] = c.x[0], p[1] = c.y[0], p[2] = c.z[0]; }
    if (kind == Kind::ALL_NAN || (kind == Kind::RANDOM && unit(rng) < 0.2F)) {
      p[rng() % 3] = NAN_F;
    }
    c.x.push_back(p[0]);
    c.y.push_back(p[1]);
    c.z.push_back(p[2]);
  }
  return c;
}

struct Case {
  std::size_t n;
  Kind kind;
};

std::string case_name(const ::testing::TestParamInfo<Case>& p) {
  const char* kinds[] = {"random", "allnan", "huge", "dup"};
  return std::string(kinds[static_cast<int>(p.param.kind)]) + "_" + std::to_string(p.param.n);
}

class SegSimd : public ::testing::TestWithParam<Case> {};

TEST_P(SegSimd, CropBoxMaskEqualsScalar) {
  const Cloud c = make_cloud(GetParam().n, GetParam().kind, 11);
  const ok::AxisBox box{{-1.0F, -0.5F, -1.0F}, {1.0F, 0.5F, 1.2F}};
  std::vector<std::uint8_t> ref(c.x.size()), got(c.x.size());
  const std::size_t kept = ok::crop_box_mask_scalar(c.view(), box, ref);
  EXPECT_EQ(ok::crop_box_mask(c.view(), box, got), kept);
  EXPECT_EQ(got, ref);
  ok::for_each_available_arch([&](auto arch) {
    std::vector<std::uint8_t> m(c.x.size(), 7);
    EXPECT_EQ(ok::detail::CropBoxKernel{}(arch, c.view(), box, m), kept) << decltype(arch)::name();
    EXPECT_EQ(m, ref) << decltype(arch)::name();
  });
}

TEST_P(SegSimd, CropOrientedMaskWithinTolerance) {
  const Cloud c = make_cloud(GetParam().n, GetParam().kind, 12);
  const float s = std::sqrt(0.5F);
  const ok::OrientedBox box{{0.1F, 0.0F, 0.2F}, {s, s, 0, -s, s, 0, 0, 0, 1}, {0.8F, 0.4F, 1.0F}};
  std::vector<std::uint8_t> ref(c.x.size());
  ok::crop_oriented_mask_scalar(c.view(), box, ref);
  ok::for_each_available_arch([&](auto arch) {
    std::vector<std::uint8_t> m(c.x.size());
    ok::detail::CropOrientedKernel{}(arch, c.view(), box, m);
    for (std::size_t i = 0; i < m.size(); ++i) {
      if (m[i] == ref[i]) { continue; }
      // Only points within the stated tolerance of a face may differ.
      const double mag = std::fabs(c.x[i]) + std::fabs(c.y[i]) + std::fabs(c.z[i]) + 1.0;
      double worst = 1e300;
      for (std::size_t k = 0; k < 3; ++k) {
        const double t = box.axes[3 * k] * (double(c.x[i]) - box.center[0]) +
                         box.axes[3 * k + 1] * (double(c.y[i]) - box.center[1]) +
                         box.axes[3 * k + 2] * (double(c.z[i]) - box.center[2]);
        worst = std::min(worst, std::fabs(std::fabs(t) - box.half_extent[k]));
      }
      EXPECT_LE(worst, 1e-6 * mag) << decltype(arch)::name() << " point " << i;
    }
  });
}

TEST_P(SegSimd, PlaneInliersAndDistancesWithinTolerance) {
  const Cloud c = make_cloud(GetParam().n, GetParam().kind, 13);
  const ok::Plane plane{{0.0F, 0.6F, 0.8F}, -0.1F};
  const float tau = 0.3F;
  const std::size_t ref = ok::count_plane_inliers_scalar(c.view(), plane, tau);
  std::vector<float> ref_d(c.x.size());
  ok::plane_signed_distance_scalar(c.view(), plane, ref_d);
  // Points whose distance is within the tolerance of tau may count either way.
  std::size_t ambiguous = 0;
  for (std::size_t i = 0; i < ref_d.size(); ++i) {
    const double mag = std::fabs(c.x[i]) + std::fabs(c.y[i]) + std::fabs(c.z[i]) + 0.1;
    ambiguous += std::fabs(std::fabs(double(ref_d[i])) - tau) <= 1e-6 * mag ? 1U : 0U;
  }
  ok::for_each_available_arch([&](auto arch) {
    const std::size_t got = ok::detail::PlaneInlierKernel{}(arch, c.view(), plane, tau);
    EXPECT_LE(got > ref ? got - ref : ref - got, ambiguous) << decltype(arch)::name();
    std::vector<float> d(c.x.size());
    EXPECT_EQ(ok::detail::PlaneDistanceKernel{}(arch, c.view(), plane, d), c.x.size());
    for (std::size_t i = 0; i < d.size(); ++i) {
      const double mag = std::fabs(c.x[i]) + std::fabs(c.y[i]) + std::fabs(c.z[i]) + 0.1;
      if (std::isnan(ref_d[i])) {
        EXPECT_TRUE(std::isnan(d[i])) << i;
      } else if (std::isfinite(ref_d[i])) {
        EXPECT_NEAR(d[i], ref_d[i], 1e-6 * mag) << decltype(arch)::name() << " point " << i;
      }
    }
  });
  EXPECT_LE(std::max(ok::count_plane_inliers(c.view(), plane, tau), ref) -
                std::min(ok::count_plane_inliers(c.view(), plane, tau), ref),
            ambiguous);
}

INSTANTIATE_TEST_SUITE_P(
    Inputs, SegSimd,
    ::testing::Values(Case{0, Kind::RANDOM}, Case{1, Kind::RANDOM}, Case{3, Kind::RANDOM},
                      Case{4, Kind::RANDOM}, Case{5, Kind::RANDOM}, Case{7, Kind::RANDOM},
                      Case{8, Kind::RANDOM}, Case{9, Kind::RANDOM}, Case{15, Kind::RANDOM},
                      Case{16, Kind::RANDOM}, Case{17, Kind::RANDOM}, Case{33, Kind::RANDOM},
                      Case{10007, Kind::RANDOM}, Case{37, Kind::ALL_NAN}, Case{1, Kind::ALL_NAN},
                      Case{41, Kind::HUGE}, Case{29, Kind::DUPLICATES}),
    case_name);

TEST(SegSimdDepth, ProjectionEqualsScalarBitForBit) {
  std::array<float, ok::DISPARITY_TABLE_SIZE> table{};
  ok::fill_disparity_table_reciprocal(table);
  EXPECT_EQ(table[2047], 0.0F);
  EXPECT_NEAR(table[700], 0.847F, 0.002F);  // KINECT_V1.md 8.1 sample: 847 mm
  for (const std::uint32_t width : {1U, 3U, 8U, 17U, 64U}) {
    const std::uint32_t height = 5;
    std::mt19937 rng(width);
    std::vector<std::uint16_t> raw(std::size_t{width} * height);
    for (auto& r : raw) {
      r = static_cast<std::uint16_t>(rng() % 5 == 0 ? 2047 : 400 + rng() % 800);
    }
    std::vector<float> rx(raw.size()), ry(raw.size()), rz(raw.size());
    const ok::DepthCamera cam{};
    const std::size_t valid =
        ok::depth_to_points_scalar(raw, width, height, table, cam, {rx, ry, rz});
    ok::for_each_available_arch([&](auto arch) {
      std::vector<float> x(raw.size()), y(raw.size()), z(raw.size());
      EXPECT_EQ(
          ok::detail::DepthProjectionKernel{}(arch, raw, width, height, table, cam, {x, y, z}),
          valid);
      for (std::size_t i = 0; i < raw.size(); ++i) {
        EXPECT_TRUE((std::isnan(rz[i]) && std::isnan(z[i])) ||
                    (x[i] == rx[i] && y[i] == ry[i] && z[i] == rz[i]))
            << decltype(arch)::name() << " width " << width << " pixel " << i;
      }
    });
    std::vector<float> x(raw.size()), y(raw.size()), z(raw.size());
    EXPECT_EQ(ok::depth_to_points(raw, width, height, table, cam, {x, y, z}), valid);
    // No-reading pixels become NaN; a valid pixel is on its ray: x / z = (u - cx) / fx.
    for (std::size_t i = 0; i < raw.size(); ++i) {
      EXPECT_EQ(std::isnan(z[i]), raw[i] == 2047 || raw[i] >= 1080);
      if (!std::isnan(z[i])) {
        EXPECT_NEAR(x[i] / z[i], (float(i % width) - cam.cx) / cam.fx, 1e-5F);
      }
    }
  }
}

TEST(SegSimdPrism, DispatchedPrismMatchesScalar) {
  const Cloud c = make_cloud(999, Kind::RANDOM, 14);
  const ok::Plane plane{{0.0F, 0.0F, 1.0F}, 0.5F};  // z = -0.5, heights z + 0.5
  const double hu[] = {-1.0, 1.0, 1.0, -1.0}, hv[] = {-1.0, -1.0, 1.0, 1.0};
  const ok::Prism prism{plane, ok::make_plane_basis(plane), hu, hv, 0.1F, 1.0F};
  std::vector<float> h(c.x.size());
  std::vector<std::uint8_t> ref(c.x.size()), got(c.x.size());
  const std::size_t kept = ok::polygonal_prism_scalar(c.view(), prism, h, ref);
  EXPECT_EQ(ok::polygonal_prism(c.view(), prism, h, got), kept);
  EXPECT_EQ(got, ref);
  std::size_t expected = 0;
  for (std::size_t i = 0; i < c.x.size(); ++i) {
    const float height = c.z[i] + 0.5F;
    // For this plane the basis is u = x, v = y, so the hull is the square |x|, |y| <= 1.
    const bool inside_xy = std::fabs(c.x[i]) <= 1.0F && std::fabs(c.y[i]) <= 1.0F;
    expected += (height >= 0.1F && height <= 1.0F && inside_xy && !std::isnan(c.x[i]) &&
                 !std::isnan(c.y[i]))
                    ? 1U
                    : 0U;
  }
  EXPECT_GT(kept, 0U);
  EXPECT_EQ(kept, expected);
}

}  // namespace
