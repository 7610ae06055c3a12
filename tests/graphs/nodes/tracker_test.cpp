#include "graphs/nodes/tracker.hpp"

#include <gtest/gtest.h>

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
