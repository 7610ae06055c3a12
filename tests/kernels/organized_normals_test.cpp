// organized_normals(): every compiled SIMD variant equals the scalar twin bit for bit (no
// contraction) on random, adversarial and NaN-holed organized clouds with widths around the lane
// counts 4/8/16; known geometry gives the known normal, turned toward the sensor; depth edges,
// missing neighbours and the image border give NaN; a row range leaves the other rows alone.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "kernels/detail/organized_normals_kernel.hpp"

namespace ok = orthoflow::kernels;

namespace {

constexpr float NAN_F = std::numeric_limits<float>::quiet_NaN();

struct Grid {
  std::uint32_t w = 0, h = 0;
  std::vector<float> x, y, z;
  ok::CloudView view() const { return {{x, y, z}, w, h}; }
};

enum class Kind { SURFACE, NAN_HOLES, STEPS, HUGE, ZEROS, INF };

/// A bumpy surface about 1 m away seen through a pinhole, perturbed by @p kind.
Grid make_grid(std::uint32_t w, std::uint32_t h, Kind kind, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(0.0F, 1.0F);
  Grid g{w, h, {}, {}, {}};
  for (std::uint32_t r = 0; r < h; ++r) {
    for (std::uint32_t c = 0; c < w; ++c) {
      float z = 1.0F + 0.05F * std::sin(0.3F * float(c)) + 0.002F * unit(rng);
      if (kind == Kind::STEPS && (c / 5 + r / 7) % 3 == 0) z += 0.2F * unit(rng);
      float x = (float(c) - float(w) / 2) * z / 525.0F, y = (float(r) - float(h) / 2) * z / 525.0F;
      if (kind == Kind::HUGE) x *= 1e30F, y *= 1e30F, z *= 1e30F;
      if (kind == Kind::ZEROS) x = y = z = 0.0F;
      if (kind == Kind::NAN_HOLES && unit(rng) < 0.15F) z = NAN_F;
      if (kind == Kind::INF && unit(rng) < 0.1F) x = std::numeric_limits<float>::infinity();
      g.x.push_back(x), g.y.push_back(y), g.z.push_back(z);
    }
  }
  return g;
}

struct Normals {
  std::vector<float> x, y, z;
  explicit Normals(std::size_t n, float fill = 7.0F) : x(n, fill), y(n, fill), z(n, fill) {}
  ok::PointsSpan span() { return {x, y, z}; }
};

void expect_same_bits(const Normals& a, const Normals& b, std::size_t begin, std::size_t end,
                      const std::string& what) {
  for (std::size_t i = begin; i < end; ++i) {
    ASSERT_EQ(std::bit_cast<std::uint32_t>(a.x[i]), std::bit_cast<std::uint32_t>(b.x[i]))
        << what << " pixel " << i;
    ASSERT_EQ(std::bit_cast<std::uint32_t>(a.y[i]), std::bit_cast<std::uint32_t>(b.y[i]))
        << what << " pixel " << i;
    ASSERT_EQ(std::bit_cast<std::uint32_t>(a.z[i]), std::bit_cast<std::uint32_t>(b.z[i]))
        << what << " pixel " << i;
  }
}

struct Case {
  std::uint32_t w, h;
  Kind kind;
};

class OrganizedNormalsSimd : public ::testing::TestWithParam<Case> {};

TEST_P(OrganizedNormalsSimd, EveryVariantEqualsTheScalarTwin) {
  const Case k = GetParam();
  const Grid g = make_grid(k.w, k.h, k.kind, 5 + k.w);
  for (const std::uint32_t offset : {1U, 3U}) {
    ok::NormalParams params;
    params.offset = offset;
    Normals ref(g.x.size()), best(g.x.size(), -3.0F);
    const std::size_t written = ok::organized_normals_scalar(g.view(), params, ref.span());
    EXPECT_EQ(ok::organized_normals(g.view(), params, best.span()), written);
    expect_same_bits(ref, best, 0, g.x.size(), "dispatched");
    // Each compiled architecture, row by row over the inside of the image.
    ok::for_each_available_arch([&](auto arch) {
      if (k.w <= 2 * offset || k.h <= 2 * offset) return;
      Normals got(g.x.size());
      std::size_t count = 0;
      for (std::size_t r = offset; r + offset < k.h; ++r) {
        count += ok::detail::OrganizedNormalsRowKernel{}(arch, g.view(), params, r, offset,
                                                         k.w - offset, got.span());
        expect_same_bits(ref, got, r * k.w + offset, r * k.w + k.w - offset,
                         std::string(decltype(arch)::name()) + " row " + std::to_string(r));
      }
      EXPECT_EQ(count, written) << decltype(arch)::name();
    });
  }
}

std::vector<Case> cases() {
  std::vector<Case> out;
  for (const std::uint32_t w :
       {1U, 3U, 7U, 8U, 9U, 10U, 11U, 15U, 16U, 17U, 23U, 24U, 25U, 31U, 32U, 33U, 40U, 64U, 65U}) {
    for (const Kind kind :
         {Kind::SURFACE, Kind::NAN_HOLES, Kind::STEPS, Kind::HUGE, Kind::ZEROS, Kind::INF}) {
      out.push_back({w, 12, kind});
    }
  }
  out.push_back({0, 0, Kind::SURFACE});
  out.push_back({5, 1, Kind::SURFACE});
  return out;
}

std::string case_name(const ::testing::TestParamInfo<Case>& p) {
  const char* kinds[] = {"surface", "holes", "steps", "huge", "zeros", "inf"};
  return std::string(kinds[static_cast<int>(p.param.kind)]) + "_" + std::to_string(p.param.w) +
         "x" + std::to_string(p.param.h);
}

INSTANTIATE_TEST_SUITE_P(Grids, OrganizedNormalsSimd, ::testing::ValuesIn(cases()), case_name);

/// A tilted plane seen through a pinhole: every inner pixel's normal is the plane's, toward the
/// sensor.
TEST(OrganizedNormals, PlaneGivesItsNormalTowardTheSensor) {
  const float nx = 0.0F, ny = -std::sin(0.8F), nz = -std::cos(0.8F), d = 1.0F;  // n . p + d = 0
  Grid g{40, 30, {}, {}, {}};
  for (std::uint32_t r = 0; r < g.h; ++r) {
    for (std::uint32_t c = 0; c < g.w; ++c) {
      const float rx = (float(c) - 20.0F) / 525.0F, ry = (float(r) - 15.0F) / 525.0F;
      const float t = -d / (nx * rx + ny * ry + nz);  // ray (rx, ry, 1) meets the plane
      g.x.push_back(rx * t), g.y.push_back(ry * t), g.z.push_back(t);
    }
  }
  Normals out(g.x.size());
  const std::size_t written = ok::organized_normals(g.view(), {}, out.span());
  EXPECT_EQ(written, std::size_t{(40 - 6) * (30 - 6)});
  for (std::uint32_t r = 0; r < g.h; ++r) {
    for (std::uint32_t c = 0; c < g.w; ++c) {
      const std::size_t i = r * g.w + c;
      const bool border = r < 3 || c < 3 || r + 3 >= g.h || c + 3 >= g.w;
      if (border) {
        EXPECT_TRUE(std::isnan(out.x[i])) << r << "," << c;
        continue;
      }
      EXPECT_NEAR(out.x[i], nx, 1e-4F);
      EXPECT_NEAR(out.y[i], ny, 1e-4F);
      EXPECT_NEAR(out.z[i], nz, 1e-4F);
      EXPECT_LT(out.x[i] * g.x[i] + out.y[i] * g.y[i] + out.z[i] * g.z[i], 0.0F);  // faces us
    }
  }
}

TEST(OrganizedNormals, DepthEdgesAndMissingNeighboursHaveNoNormal) {
  // A gently sloping surface 1 m away with a 50 cm step back at column 15.
  Grid g{30, 20, {}, {}, {}};
  for (std::uint32_t r = 0; r < g.h; ++r) {
    for (std::uint32_t c = 0; c < g.w; ++c) {
      const float z = 1.0F + 0.001F * float(c) + (c >= 15 ? 0.5F : 0.0F);
      g.x.push_back((float(c) - 15.0F) * z / 525.0F);
      g.y.push_back((float(r) - 10.0F) * z / 525.0F);
      g.z.push_back(z);
    }
  }
  g.z[10 * g.w + 5] = NAN_F;
  Normals out(g.x.size());
  ok::organized_normals(g.view(), {}, out.span());
  for (std::uint32_t c = 12; c < 18; ++c) {
    EXPECT_TRUE(std::isnan(out.x[10 * g.w + c])) << "pixel beside the step, column " << c;
  }
  EXPECT_FALSE(std::isnan(out.x[10 * g.w + 7]));  // neighbours at columns 4 and 10: a normal
  EXPECT_TRUE(std::isnan(out.x[10 * g.w + 5]));   // the missing pixel itself
  EXPECT_TRUE(std::isnan(out.x[10 * g.w + 8]));   // its left neighbour (column 5) is missing
  EXPECT_TRUE(std::isnan(out.x[13 * g.w + 5]));   // its upper neighbour (row 10) is missing
}

TEST(OrganizedNormals, RowRangeLeavesOtherRowsAlone) {
  const Grid g = make_grid(20, 20, Kind::SURFACE, 2);
  Normals all(g.x.size()), part(g.x.size(), 5.0F);
  ok::organized_normals(g.view(), {}, all.span());
  ok::organized_normals(g.view(), {}, part.span(), ok::RowRange{6, 11});
  for (std::size_t i = 0; i < g.x.size(); ++i) {
    const std::size_t r = i / 20;
    if (r >= 6 && r < 11) {
      EXPECT_EQ(std::bit_cast<std::uint32_t>(part.x[i]), std::bit_cast<std::uint32_t>(all.x[i]));
    } else {
      EXPECT_EQ(part.x[i], 5.0F) << "row " << r << " was written";
    }
  }
  Normals none(g.x.size(), 5.0F);
  EXPECT_EQ(ok::organized_normals(g.view(), {}, none.span(), ok::RowRange{30, 40}), 0U);
}

// organized_normals_at() on scattered pixels (the borders, the corners, repeats, every kind of
// grid, widths around the lane counts) equals the whole-image kernel bit for bit there and leaves
// every other pixel alone; no pixels write nothing.
TEST(OrganizedNormals, AtListedPixelsEqualsTheWholeImage) {
  for (const Kind kind :
       {Kind::SURFACE, Kind::NAN_HOLES, Kind::STEPS, Kind::HUGE, Kind::ZEROS, Kind::INF}) {
    for (const std::uint32_t w : {1U, 6U, 7U, 8U, 9U, 17U, 33U}) {
      const std::uint32_t h = 11;
      const Grid g = make_grid(w, h, kind, w * 31U);
      Normals all(g.x.size()), at(g.x.size(), 5.0F);
      ok::organized_normals(g.view(), {}, all.span());
      std::vector<std::uint32_t> pixels;
      std::vector<bool> listed(g.x.size(), false);
      std::mt19937 rng(w);
      for (std::size_t k = 0; k < g.x.size(); k += 1 + rng() % 4) {
        pixels.push_back(static_cast<std::uint32_t>(k));
        listed[k] = true;
      }
      pixels.push_back(0);  // a repeat, and the last pixel (a corner)
      pixels.push_back(static_cast<std::uint32_t>(g.x.size() - 1));
      listed.back() = true;
      const std::size_t written = ok::organized_normals_at(g.view(), {}, at.span(), pixels);
      EXPECT_LE(written, pixels.size());
      for (std::size_t i = 0; i < g.x.size(); ++i) {
        if (listed[i]) {
          expect_same_bits(all, at, i, i + 1, "listed");
        } else {
          ASSERT_EQ(at.x[i], 5.0F) << "pixel " << i << " was written";
        }
      }
      Normals none(g.x.size(), 5.0F);
      EXPECT_EQ(ok::organized_normals_at(g.view(), {}, none.span(), {}), 0U);
    }
  }
}

}  // namespace
