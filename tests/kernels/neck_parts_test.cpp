// The neck split's grid kernel (kernels/detail/neck_scratch.hpp) on footprints drawn by hand: two
// touching discs are cut at their neck, each core keeping its own disc; one object's footprint (a
// disc, a disc with a handle, a ring, a rectangle) and two footprints that do not touch are not
// cut; pieces that are not round (two squares joined by a bar) are not cut; degenerate grids.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "kernels/detail/neck_scratch.hpp"

namespace ok = orthoflow::kernels::detail;

namespace {

/// A w x h grid (outer ring empty) and a way to draw on it.
struct Grid {
  std::size_t w, h;
  ok::NeckScratch s;
  Grid(std::size_t width, std::size_t height) : w(width), h(height) {
    std::fill(s.cells.begin(), s.cells.end(), std::uint8_t{0});
  }
  void disc(double cx, double cy, double r) {
    for (std::size_t y = 2; y + 2 < h; ++y)
      for (std::size_t x = 2; x + 2 < w; ++x)
        if (std::hypot(double(x) - cx, double(y) - cy) <= r) s.cells[y * w + x] = 1;
  }
  void box(std::size_t x0, std::size_t y0, std::size_t x1, std::size_t y1) {
    for (std::size_t y = y0; y <= y1; ++y)
      for (std::size_t x = x0; x <= x1; ++x) s.cells[y * w + x] = 1;
  }
  [[nodiscard]] int part(double x, double y) const {
    return s.part[static_cast<std::size_t>(y) * w + static_cast<std::size_t>(x)];
  }
  /// Share of the cells within r of (cx, cy) that are in part p.
  [[nodiscard]] double share(double cx, double cy, double r, int p) const {
    std::size_t in = 0, all = 0;
    for (std::size_t y = 0; y < h; ++y)
      for (std::size_t x = 0; x < w; ++x)
        if (std::hypot(double(x) - cx, double(y) - cy) <= r) ++all, in += s.part[y * w + x] == p;
    return double(in) / double(all);
  }
};

const ok::NeckRule RULE{};  // a core of 3 cells (1.5 cm at 5 mm), a neck under half its radius

TEST(NeckParts, TwoTouchingDiscsAreCutAtTheirNeck) {
  Grid g(40, 24);
  g.disc(11.0, 12.0, 7.0);
  g.disc(25.0, 12.0, 7.0);  // centres 14 apart: they touch
  ASSERT_EQ(ok::neck_parts(g.w, g.h, RULE, g.s), 2U);
  const int a = g.part(11, 12), b = g.part(25, 12);
  EXPECT_NE(a, b);
  EXPECT_GE(a, 0);
  EXPECT_GE(b, 0);
  EXPECT_GE(g.share(11.0, 12.0, 6.0, a), 0.97);
  EXPECT_GE(g.share(25.0, 12.0, 6.0, b), 0.97);
}

TEST(NeckParts, ABigAndASmallDiscEachKeepTheirOwn) {
  // A watershed, not the nearest centre: the small disc's share ends at the neck, not halfway
  // between the centres (which lies 2.5 cells inside the big disc).
  Grid g(48, 30);
  g.disc(15.0, 15.0, 10.0);
  g.disc(30.0, 15.0, 5.0);
  ASSERT_EQ(ok::neck_parts(g.w, g.h, RULE, g.s), 2U);
  const int big = g.part(15, 15), small = g.part(30, 15);
  ASSERT_NE(big, small);
  EXPECT_EQ(big, 0);  // the core farthest from the edge comes first
  EXPECT_GE(g.share(15.0, 15.0, 9.0, big), 0.99);
  EXPECT_GE(g.share(30.0, 15.0, 4.0, small), 0.97);
  EXPECT_EQ(g.part(23, 15), big);  // 2 cells inside the big disc's edge
}

TEST(NeckParts, ThreeDiscsInARowGiveThreeParts) {
  Grid g(56, 20);
  g.disc(10.0, 10.0, 6.0);
  g.disc(22.0, 10.0, 6.0);
  g.disc(34.0, 10.0, 6.0);
  ASSERT_EQ(ok::neck_parts(g.w, g.h, RULE, g.s), 3U);
  EXPECT_NE(g.part(10, 10), g.part(22, 10));
  EXPECT_NE(g.part(22, 10), g.part(34, 10));
  EXPECT_NE(g.part(10, 10), g.part(34, 10));
}

TEST(NeckParts, OneObjectIsNotCut) {
  {  // a disc
    Grid g(30, 30);
    g.disc(15.0, 15.0, 9.0);
    EXPECT_LE(ok::neck_parts(g.w, g.h, RULE, g.s), 1U);
  }
  {  // a mug: a disc and a thin handle loop beside it
    Grid g(40, 30);
    g.disc(15.0, 15.0, 9.0);
    for (int a = 0; a < 360; a += 2) {
      const double t = a * 3.141592653589793 / 180.0;
      const auto x = static_cast<std::size_t>(std::lround(27.0 + 4.0 * std::cos(t)));
      const auto y = static_cast<std::size_t>(std::lround(15.0 + 4.0 * std::sin(t)));
      g.s.cells[y * g.w + x] = 1;
    }
    EXPECT_LE(ok::neck_parts(g.w, g.h, RULE, g.s), 1U);
  }
  {  // a bowl seen from above: a ring whose inside was hidden (filled)
    Grid g(34, 34);
    g.disc(17.0, 17.0, 12.0);
    for (std::size_t y = 0; y < g.h; ++y)
      for (std::size_t x = 0; x < g.w; ++x)
        if (std::hypot(double(x) - 17.0, double(y) - 17.0) < 9.0) g.s.cells[y * g.w + x] = 0;
    EXPECT_LE(ok::neck_parts(g.w, g.h, RULE, g.s), 1U);
    EXPECT_EQ(g.part(17, 17), -1);  // filled, but one part is no cut
  }
  {  // a long box
    Grid g(50, 16);
    g.box(3, 4, 46, 11);
    EXPECT_LE(ok::neck_parts(g.w, g.h, RULE, g.s), 1U);
  }
}

TEST(NeckParts, FootprintsThatDoNotTouchAreLeftAsTheyAre) {
  // Two blobs the earlier stages joined on purpose (an object seen on both sides of an occluder).
  Grid g(50, 24);
  g.disc(12.0, 12.0, 7.0);
  g.disc(36.0, 12.0, 7.0);
  EXPECT_LE(ok::neck_parts(g.w, g.h, RULE, g.s), 1U);
}

TEST(NeckParts, PiecesThatAreNotRoundAreNotCut) {
  // Two long boxes joined end to end by a bar: a neck, but each part is over twice the disc of
  // its core (the outline of a box half hidden by a nearer object narrows like this on mOSD). Two
  // squares would be cut: a square is 1.27 times the disc it holds.
  Grid g(80, 20);
  g.box(3, 5, 34, 14);
  g.box(45, 5, 76, 14);
  g.box(34, 9, 45, 10);
  EXPECT_LE(ok::neck_parts(g.w, g.h, RULE, g.s), 1U);
  ok::NeckRule any_shape = RULE;
  any_shape.max_round = 100.0F;
  EXPECT_EQ(ok::neck_parts(g.w, g.h, any_shape, g.s), 2U);
}

TEST(NeckParts, AWideNeckIsNotANeck) {
  // Discs of radius 7 overlapping so far that the waist is 5 cells from the edge: over half.
  Grid g(36, 24);
  g.disc(12.0, 12.0, 7.0);
  g.disc(20.0, 12.0, 7.0);
  EXPECT_LE(ok::neck_parts(g.w, g.h, RULE, g.s), 1U);
}

TEST(NeckParts, SmallCoresAreNotCores) {
  // Two discs of radius 2 cells (1 cm): below the 3-cell core.
  Grid g(20, 12);
  g.disc(6.0, 6.0, 2.0);
  g.disc(10.0, 6.0, 2.0);
  EXPECT_LE(ok::neck_parts(g.w, g.h, RULE, g.s), 1U);
}

TEST(NeckParts, DegenerateGrids) {
  Grid empty(20, 20);
  EXPECT_EQ(ok::neck_parts(empty.w, empty.h, RULE, empty.s), 0U);
  Grid tiny(2, 2);
  EXPECT_EQ(ok::neck_parts(2, 2, RULE, tiny.s), 0U);
  EXPECT_EQ(ok::neck_parts(ok::NECK_GRID + 1, 10, RULE, tiny.s), 0U);
  Grid full(ok::NECK_GRID, ok::NECK_GRID);  // the largest grid, one full square
  full.box(2, 2, ok::NECK_GRID - 3, ok::NECK_GRID - 3);
  EXPECT_LE(ok::neck_parts(full.w, full.h, RULE, full.s), 1U);
}

TEST(NeckParts, TheCutDoesNotDependOnOrientation) {
  // The same pair, transposed: the same cells on either side, except on the neck's own line
  // (x = 18), whose cells lie as near one core as the other and go to either.
  Grid a(40, 24), t(24, 40);
  a.disc(11.0, 12.0, 7.0);
  a.disc(25.0, 12.0, 7.0);
  t.disc(12.0, 11.0, 7.0);
  t.disc(12.0, 25.0, 7.0);
  ASSERT_EQ(ok::neck_parts(a.w, a.h, RULE, a.s), 2U);
  ASSERT_EQ(ok::neck_parts(t.w, t.h, RULE, t.s), 2U);
  for (std::size_t y = 0; y < a.h; ++y)
    for (std::size_t x = 0; x < a.w; ++x) {
      const bool left_a = a.part(double(x), double(y)) == a.part(11, 12);
      const bool left_t = t.part(double(y), double(x)) == t.part(12, 11);
      if (a.part(double(x), double(y)) >= 0 && (x < 17 || x > 19)) {
        EXPECT_EQ(left_a, left_t) << x << "," << y;
      }
    }
}

}  // namespace
