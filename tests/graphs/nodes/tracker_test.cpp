#include "graphs/nodes/tracker.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <vector>

namespace orthoflow::graphs {
namespace {

// A cube of points of side `size` centred at (cx, cy, cz).
struct Blob {
  std::vector<float> x, y, z;
  Blob(float cx, float cy, float cz, float size = 0.06F) {
    for (int i = 0; i < 5; ++i)
      for (int j = 0; j < 5; ++j)
        for (int k = 0; k < 5; ++k) {
          x.push_back(cx + size * (static_cast<float>(i) / 4.0F - 0.5F));
          y.push_back(cy + size * (static_cast<float>(j) / 4.0F - 0.5F));
          z.push_back(cz + size * (static_cast<float>(k) / 4.0F - 0.5F));
        }
  }
  TrackInput input() const {
    TrackInput in;
    in.points = {x, y, z};
    in.box_min = {x.front(), y.front(), z.front()};
    in.box_max = {x.back(), y.back(), z.back()};
    in.centroid = {(x.front() + x.back()) / 2, (y.front() + y.back()) / 2,
                   (z.front() + z.back()) / 2};
    return in;
  }
};

constexpr std::int64_t FRAME_NS = 33'333'333;

TEST(Tracker, KeepsIdsOfStillAndSlowlyMovingObjects) {
  Tracker tracker({});
  std::vector<TrackOutput> out(2);
  for (int f = 0; f < 60; ++f) {
    const Blob still(0.0F, 0.0F, 1.0F),
        mover(0.3F + 0.002F * static_cast<float>(f), 0.0F, 1.0F);    // 6 cm/s
    const std::vector<TrackInput> in{mover.input(), still.input()};  // order must not matter
    tracker.update(f * FRAME_NS, in, out);
    EXPECT_EQ(out[0].track_id, 1U) << f;
    EXPECT_EQ(out[1].track_id, 2U) << f;
    EXPECT_EQ(out[0].new_track, f == 0);
    EXPECT_EQ(out[0].key_view, f == 0);
  }
  EXPECT_EQ(tracker.started(), 2U);
  EXPECT_EQ(tracker.active(), 2U);
}

TEST(Tracker, NewObjectGetsNewIdAndLostTrackEnds) {
  TrackerParams p;
  p.lost_timeout_s = 0.5;
  Tracker tracker(p);
  std::vector<TrackOutput> out(2);
  const Blob a(0.0F, 0.0F, 1.0F), b(0.3F, 0.0F, 1.0F);
  tracker.update(0, std::vector<TrackInput>{a.input()}, out);
  EXPECT_EQ(out[0].track_id, 1U);
  tracker.update(FRAME_NS, std::vector<TrackInput>{a.input(), b.input()}, out);
  EXPECT_EQ(out[0].track_id, 1U);
  EXPECT_EQ(out[1].track_id, 2U);
  EXPECT_TRUE(out[1].new_track);
  tracker.update(2 * FRAME_NS, std::vector<TrackInput>{b.input()}, out);  // a out of view
  EXPECT_EQ(out[0].track_id, 2U);
  EXPECT_EQ(tracker.active(), 2U);  // a is kept until its timeout
  tracker.update(30 * FRAME_NS, std::vector<TrackInput>{b.input()}, out);
  EXPECT_EQ(tracker.active(), 1U);
  tracker.update(31 * FRAME_NS, std::vector<TrackInput>{a.input(), b.input()}, out);
  EXPECT_EQ(out[0].track_id, 3U);  // a came back after its track ended: a new track
  EXPECT_EQ(out[1].track_id, 2U);
}

TEST(Tracker, KeyViewWhenStaticAgainAfterMoving) {
  TrackerParams p;
  p.static_frames = 5;
  Tracker tracker(p);
  std::vector<TrackOutput> out(1);
  float x = 0.0F;
  int key_views = 0, moving_frames = 0;
  for (int f = 0; f < 60; ++f) {
    if (f >= 10 && f < 30) x += 0.005F;  // 15 cm/s for 20 frames, then still
    tracker.update(f * FRAME_NS, std::vector<TrackInput>{Blob(x, 0.0F, 1.0F).input()}, out);
    EXPECT_EQ(out[0].track_id, 1U) << f;
    key_views += out[0].key_view ? 1 : 0;
    moving_frames += out[0].moving ? 1 : 0;
  }
  EXPECT_EQ(key_views, 2);  // the first view, and once static again
  EXPECT_GT(moving_frames, 15);
}

TEST(Tracker, TooManyObjectsAreLeftUntracked) {
  TrackerParams p;
  p.max_tracks = 2;
  Tracker tracker(p);
  std::vector<TrackOutput> out(3);
  const Blob a(0.0F, 0.0F, 1.0F), b(0.3F, 0.0F, 1.0F), c(-0.3F, 0.0F, 1.0F);
  tracker.update(0, std::vector<TrackInput>{a.input(), b.input(), c.input()}, out);
  EXPECT_EQ(out[0].track_id, 1U);
  EXPECT_EQ(out[1].track_id, 2U);
  EXPECT_EQ(out[2].track_id, 0U);
}

}  // namespace
}  // namespace orthoflow::graphs

// share_inside() skips the scan when the points' bounding box settles the answer; it must equal
// the reference scan bit for bit: boxes apart, holding, straddling, touching at the margin, a
// shifted box, empty input, one point, and sizes around a SIMD width.
TEST(Tracker, ShareInsideEqualsTheReferenceScan) {
  std::uint64_t state = 12345;
  auto uniform = [&](float lo, float hi) {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return lo + (hi - lo) * static_cast<float>(state >> 40) / static_cast<float>(1ULL << 24);
  };
  std::size_t cases = 0, skipped_scan = 0;
  for (const std::size_t n : {0UL, 1UL, 7UL, 8UL, 9UL, 15UL, 16UL, 17UL, 100UL, 1000UL}) {
    for (int trial = 0; trial < 200; ++trial) {
      std::vector<float> x(n), y(n), z(n);
      const float cx = uniform(-0.3F, 0.3F), cy = uniform(-0.3F, 0.3F), cz = uniform(0.8F, 1.2F);
      const float r = uniform(0.01F, 0.1F);
      for (std::size_t k = 0; k < n; ++k) {
        x[k] = cx + uniform(-r, r), y[k] = cy + uniform(-r, r), z[k] = cz + uniform(-r, r);
      }
      std::array<float, 3> lo{}, hi{}, p_lo{cx, cy, cz}, p_hi{cx, cy, cz};
      if (n > 0) {
        p_lo = {x[0], y[0], z[0]}, p_hi = p_lo;
        for (std::size_t k = 0; k < n; ++k) {
          p_lo = {std::min(p_lo[0], x[k]), std::min(p_lo[1], y[k]), std::min(p_lo[2], z[k])};
          p_hi = {std::max(p_hi[0], x[k]), std::max(p_hi[1], y[k]), std::max(p_hi[2], z[k])};
        }
      }
      for (std::size_t a = 0; a < 3; ++a) {  // boxes from far apart to holding everything
        const float c = a == 0 ? cx : a == 1 ? cy : cz, s = uniform(0.0F, 0.15F);
        lo[a] = c + uniform(-0.2F, 0.1F), hi[a] = lo[a] + s;
      }
      if (trial % 7 == 0 && n > 0) lo = p_lo, hi = p_hi;  // exactly the bounds: all inside
      const std::array<float, 3> shift{uniform(-0.05F, 0.05F), 0.0F, uniform(-0.05F, 0.05F)};
      const float m = trial % 5 == 0 ? 0.0F : 0.02F;
      const orthoflow::kernels::PointsView p{x, y, z};
      const float fast = orthoflow::graphs::share_inside(p, lo, hi, shift, m, p_lo, p_hi, true);
      const float ref = orthoflow::graphs::share_inside_reference(p, lo, hi, shift, m);
      ASSERT_EQ(fast, ref) << "n " << n << " trial " << trial;
      ++cases;
      skipped_scan += (ref == 0.0F || ref == 1.0F) ? 1 : 0;
    }
  }
  EXPECT_GT(skipped_scan, cases / 4);  // the cases where the bounds decide were exercised
  EXPECT_LT(skipped_scan, cases);      // and so were the straddling ones
}
