// The candidate constraints and the gather of kernels/object_candidates.hpp on hand-made clusters:
// C_size and C_edge in cluster order with a capacity, the counting-sort gather over every index or
// a member list (the same result), and the majority tag rule (at least half, tag 0 never counts).
#include "kernels/object_candidates.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <span>
#include <utility>
#include <vector>

namespace ok = orthoflow::kernels;

namespace {

ok::ClusterStats cluster(float cx, float cy, float size, std::size_t points) {
  ok::ClusterStats s;
  s.points = points;
  s.centroid = {cx, cy, 1.0F};
  s.obb_min = {0.0F, 0.0F, 0.0F};
  s.obb_max = {size, size / 2, size / 4};
  return s;
}

TEST(ObjectCandidates, SizeEdgeAndCapacityInClusterOrder) {
  const ok::Plane plane{{0.0F, 0.0F, -1.0F}, 1.0F};  // z = 1, normal toward the sensor
  const ok::PlaneBasis basis = ok::make_plane_basis(plane);
  // The table: a 1 m square around the origin, counter-clockwise in the plane's basis.
  std::vector<double> hu, hv;
  for (const auto& [x, y] : {std::pair{-0.5F, -0.5F}, {0.5F, -0.5F}, {0.5F, 0.5F}, {-0.5F, 0.5F}}) {
    double u = 0, v = 0;
    const std::array<std::uint32_t, 1> zero{0};
    const float z = 1.0F;
    ok::project_to_plane({{&x, 1}, {&y, 1}, {&z, 1}}, zero, basis, {&u, 1}, {&v, 1});
    hu.push_back(u);
    hv.push_back(v);
  }
  if (ok::inside_distance(0.0, 0.0, hu, hv) < 0) {  // make it counter-clockwise
    std::reverse(hu.begin(), hu.end());
    std::reverse(hv.begin(), hv.end());
  }
  EXPECT_NEAR(ok::inside_distance(0.0, 0.0, hu, hv), 0.5, 1e-6);
  const std::vector<ok::ClusterStats> clusters{
      cluster(0.0F, 0.0F, 0.10F, 500),   // kept
      cluster(0.1F, 0.0F, 0.01F, 500),   // too small (C_size)
      cluster(0.0F, 0.1F, 0.80F, 500),   // too large (C_size)
      cluster(0.49F, 0.0F, 0.10F, 500),  // 1 cm from the edge (C_edge)
      cluster(-0.2F, 0.0F, 0.10F, 500),  // kept
      cluster(0.2F, 0.2F, 0.10F, 500),   // passes both, but the capacity is 2
  };
  std::vector<std::int32_t> slot_of(clusters.size());
  const ok::CandidateCounts counts = ok::select_candidates(clusters, plane, hu, hv, {}, 2, slot_of);
  EXPECT_EQ(counts.kept, 2U);
  EXPECT_EQ(counts.rejected_size, 2U);
  EXPECT_EQ(counts.rejected_edge, 1U);
  EXPECT_EQ(counts.over_capacity, 1U);
  EXPECT_EQ(slot_of, (std::vector<std::int32_t>{0, -1, -1, -1, 1, -1}));
}

TEST(ObjectCandidates, GatherIsACountingSortAndMembersGiveTheSame) {
  const std::vector<float> x{0, 1, 2, 3, 4, 5, 6}, y(7, 0.0F), z(7, 1.0F);
  const std::vector<std::int32_t> labels{1, -1, 0, 1, 2, 0, 1};  // cluster 2 is not a candidate
  const std::vector<std::int32_t> slot_of{1, 0, -1};             // cluster 1 -> candidate 0
  const std::vector<std::size_t> sizes{3, 2};
  const std::vector<std::uint32_t> tags{7, 9, 8, 7, 5, 8, 3};
  for (const bool listed : {false, true}) {
    std::vector<float> gx(5), gy(5), gz(5);
    std::vector<ok::CandidateSpan> spans(2);
    std::vector<std::uint32_t> histogram(2 * 10, 99U);           // zeroed by the gather
    const std::vector<std::uint32_t> members{0, 2, 3, 4, 5, 6};  // ascending, every labelled index
    const std::size_t n =
        ok::gather_candidates({x, y, z}, labels, listed ? members : std::vector<std::uint32_t>{},
                              slot_of, sizes, {gx, gy, gz}, spans, tags, 10, histogram);
    EXPECT_EQ(n, 5U);
    EXPECT_EQ(spans[0].first, 0U);
    EXPECT_EQ(spans[0].count, 3U);
    EXPECT_EQ(spans[1].first, 3U);
    EXPECT_EQ(spans[1].count, 2U);
    EXPECT_EQ(gx, (std::vector<float>{0, 3, 6, 2, 5}));  // ascending point order within a candidate
    EXPECT_EQ(histogram[7], 2U);
    EXPECT_EQ(histogram[3], 1U);
    EXPECT_EQ(histogram[10 + 8], 2U);
    EXPECT_EQ(ok::majority_tag(std::span(histogram).first(10), 3), 7U);        // 2 of 3
    EXPECT_EQ(ok::majority_tag(std::span(histogram).subspan(10, 10), 2), 8U);  // 2 of 2
  }
}

TEST(ObjectCandidates, MajorityNeedsHalfAndNeverTagZero) {
  std::vector<std::uint32_t> h(4, 0U);
  h[0] = 10;  // tag 0 ("no label") never wins
  h[2] = 3;
  EXPECT_EQ(ok::majority_tag(h, 13), 0U);  // 3 of 13
  EXPECT_EQ(ok::majority_tag(h, 6), 2U);   // exactly half counts
  EXPECT_EQ(ok::majority_tag(h, 7), 0U);
  EXPECT_EQ(ok::majority_tag(std::vector<std::uint32_t>(1, 5U), 5), 0U);  // no tag but 0
}

}  // namespace

// Over capacity, the nearest candidates to the sensor are kept (the farthest dropped: the budget's
// step 3), numbered in cluster order; equal ranges keep the earlier cluster.
TEST(ObjectCandidates, OverCapacityKeepsTheNearest) {
  const ok::Plane plane{{0.0F, 0.0F, -1.0F}, 1.0F};
  const std::vector<double> hu{-10, 10, 10, -10}, hv{-10, -10, 10, 10};  // no edge in reach
  std::vector<ok::ClusterStats> clusters{
      cluster(0.3F, 0.0F, 0.10F, 500),  // range^2 1.09
      cluster(0.0F, 0.0F, 0.10F, 500),  // 1.00: nearest
      cluster(0.3F, 0.0F, 0.10F, 500),  // 1.09: ties with 0, loses to it
      cluster(0.1F, 0.0F, 0.10F, 500),  // 1.01
      cluster(0.5F, 0.0F, 0.10F, 500),  // 1.25
  };
  std::vector<std::int32_t> slot_of(clusters.size());
  ok::CandidateParams p;
  p.edge_margin = -100.0F;
  const auto counts = ok::select_candidates(clusters, plane, hu, hv, p, 3, slot_of);
  EXPECT_EQ(counts.kept, 3U);
  EXPECT_EQ(counts.over_capacity, 2U);
  EXPECT_EQ(slot_of, (std::vector<std::int32_t>{0, 1, -1, 2, -1}));
}
