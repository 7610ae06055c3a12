// set_distance (kernels/set_distance.hpp), the thesis's D(U, V) between sets of spin images:
// computed by hand on tiny sets (and its asymmetry), the empty and NaN cases, and the dispatched
// kernel against the scalar twin on random sets of sizes around the lane counts.
#include "kernels/set_distance.hpp"

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

namespace ok = orthoflow::kernels;

namespace {

// A structure-of-arrays copy of row-major descriptors (value d of descriptor j at d * count + j).
struct Set {
  std::vector<float> rows, soa;
  std::size_t dims = 0, count = 0;
  Set(std::vector<float> r, std::size_t d) : rows(std::move(r)), dims(d), count(rows.size() / d) {
    soa.resize(rows.size());
    for (std::size_t j = 0; j < count; ++j)
      for (std::size_t k = 0; k < dims; ++k) soa[k * count + j] = rows[j * dims + k];
  }
  [[nodiscard]] ok::DescriptorMatrixView matrix() const { return {soa, dims, count, count}; }
};

TEST(SetDistance, TinySetsByHand) {
  // U = {(0,0), (3,4)}, V = {(0,1), (3,0)}: (0,0) is 1 from (0,1); (3,4) is 4 from (3,0) (and
  // sqrt 18 from (0,1)): D(U, V) = (1 + 4) / 2. The other way: (0,1) is 1 from (0,0), (3,0) is 3
  // from (0,0): D(V, U) = 2. Not symmetric.
  const Set u({0, 0, 3, 4}, 2), v({0, 1, 3, 0}, 2);
  std::vector<float> scratch(2);
  EXPECT_FLOAT_EQ(ok::set_distance(u.rows, v.matrix(), scratch), 2.5F);
  EXPECT_FLOAT_EQ(ok::set_distance(v.rows, u.matrix(), scratch), 2.0F);
  EXPECT_FLOAT_EQ(ok::set_distance_scalar(u.rows, v.matrix(), scratch), 2.5F);
  EXPECT_FLOAT_EQ(ok::set_distance(u.rows, u.matrix(), scratch), 0.0F);
  // A single descriptor against a set: its nearest member's distance.
  const std::vector<float> one{3, 1};
  EXPECT_FLOAT_EQ(ok::set_distance(one, v.matrix(), scratch), 1.0F);
}

TEST(SetDistance, EmptySetsAndNaN) {
  const Set v({0, 1, 3, 0}, 2);
  std::vector<float> scratch(2);
  EXPECT_EQ(ok::set_distance({}, v.matrix(), scratch), 0.0F);  // nothing to explain
  const std::vector<float> u{1, 1};
  const ok::DescriptorMatrixView empty{{}, 2, 0, 0};
  EXPECT_EQ(ok::set_distance(u, empty, scratch), std::numeric_limits<float>::infinity());
  const std::vector<float> bad{1, std::numeric_limits<float>::quiet_NaN()};
  EXPECT_TRUE(std::isnan(ok::set_distance(bad, v.matrix(), scratch)));
  const Set vbad({0, 1, std::numeric_limits<float>::quiet_NaN(), 0}, 2);
  EXPECT_TRUE(std::isnan(ok::set_distance(u, vbad.matrix(), scratch)));
  EXPECT_TRUE(std::isnan(ok::set_distance_scalar(u, vbad.matrix(), scratch)));
}

TEST(SetDistance, TheKernelEqualsTheScalarTwinWithinTolerance) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> value(0.0F, 0.1F);
  for (const std::size_t dims : {1U, 45U, 153U}) {
    for (const std::size_t nu : {1U, 3U, 8U, 17U}) {
      for (const std::size_t nv : {1U, 3U, 4U, 7U, 8U, 9U, 15U, 16U, 17U, 33U, 100U}) {
        std::vector<float> a(nu * dims), b(nv * dims);
        for (float& x : a) x = value(rng);
        for (float& x : b) x = value(rng);
        const Set u(a, dims), v(b, dims);
        std::vector<float> scratch(nv);
        const float twin = ok::set_distance_scalar(u.rows, v.matrix(), scratch);
        const float simd = ok::set_distance(u.rows, v.matrix(), scratch);
        EXPECT_NEAR(simd, twin, 1e-5F * twin) << dims << " " << nu << " " << nv;
        EXPECT_GT(twin, 0.0F);
      }
    }
  }
}

// V stored with spare columns up to a stride of 16 (zeros, or NaN: never compared): the same D as
// without them (within the kernel's tolerance: the spare columns move columns out of the scalar
// tail), and exactly the scalar twin's result on the padded view.
TEST(SetDistance, SpareColumnsUpToTheStrideAreNeverCompared) {
  std::mt19937 rng(12);
  std::uniform_real_distribution<float> value(0.0F, 0.1F);
  for (const std::size_t dims : {1U, 45U, 153U}) {
    for (const std::size_t nv : {1U, 7U, 16U, 17U, 40U}) {
      const std::size_t stride = (nv + 15) / 16 * 16;
      std::vector<float> a(5 * dims), b(nv * dims);
      for (float& x : a) x = value(rng);
      for (float& x : b) x = value(rng);
      const Set u(a, dims), v(b, dims);
      for (const float spare : {0.0F, std::numeric_limits<float>::quiet_NaN()}) {
        std::vector<float> padded(dims * stride, spare);
        for (std::size_t k = 0; k < dims; ++k)
          for (std::size_t j = 0; j < nv; ++j) padded[k * stride + j] = v.soa[k * nv + j];
        const ok::DescriptorMatrixView pv{padded, dims, nv, stride};
        std::vector<float> scratch(stride), short_scratch(nv);
        const float twin = ok::set_distance_scalar(u.rows, v.matrix(), scratch);
        EXPECT_NEAR(ok::set_distance(u.rows, pv, scratch), twin, 1e-5F * twin) << dims << " " << nv;
        EXPECT_NEAR(ok::set_distance(u.rows, pv, short_scratch), twin, 1e-5F * twin)
            << "a scratch of count: the spare columns are skipped";
        EXPECT_EQ(ok::set_distance_scalar(u.rows, pv, scratch), twin)
            << "the twin, column by column";
      }
    }
  }
}

}  // namespace
