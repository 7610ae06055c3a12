#include "learning/dictionary.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "core/rng.hpp"

namespace orthoflow::learning {

namespace {

/// Rows per parallel block: fixed, so the blocks (and nothing else) do not depend on thread count.
constexpr std::size_t BLOCK = 256;

double squared(const float* a, const float* b, std::size_t dims) noexcept {
  double sum = 0.0;
  for (std::size_t d = 0; d < dims; ++d) {
    const double diff = static_cast<double>(a[d]) - static_cast<double>(b[d]);
    sum += diff * diff;
  }
  return sum;
}

/// For every row, the nearest centre and its squared distance (ties: the lower centre).
void assign(std::span<const float> rows, std::size_t dims, const std::vector<float>& centres,
            std::size_t k, std::vector<std::uint32_t>& to, std::vector<double>& d2) {
  const std::size_t n = rows.size() / dims;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, BLOCK),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i != r.end(); ++i) {
                        const float* row = rows.data() + i * dims;
                        std::uint32_t best = 0;
                        double best_d = squared(row, centres.data(), dims);
                        for (std::size_t c = 1; c < k; ++c) {
                          const double d = squared(row, centres.data() + c * dims, dims);
                          if (d < best_d) {
                            best_d = d;
                            best = static_cast<std::uint32_t>(c);
                          }
                        }
                        to[i] = best;
                        d2[i] = best_d;
                      }
                    });
}

/// k-means++: the first centre uniformly, each next one with probability proportional to the
/// squared distance to the nearest centre chosen so far.
std::vector<float> seed_centres(std::span<const float> rows, std::size_t dims, std::size_t k,
                                core::Rng& rng) {
  const std::size_t n = rows.size() / dims;
  std::vector<float> centres(k * dims);
  std::vector<double> d2(n, std::numeric_limits<double>::infinity());
  std::size_t chosen = rng.below(n);
  for (std::size_t c = 0; c < k; ++c) {
    std::copy_n(rows.data() + chosen * dims, dims, centres.data() + c * dims);
    const float* centre = centres.data() + c * dims;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, BLOCK),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t i = r.begin(); i != r.end(); ++i)
                          d2[i] = std::min(d2[i], squared(rows.data() + i * dims, centre, dims));
                      });
    if (c + 1 == k) break;
    double total = 0.0;
    for (const double v : d2) total += v;
    if (!(total > 0.0)) {  // every row sits on a centre: take the next row not chosen yet
      chosen = (chosen + 1) % n;
      continue;
    }
    const double u = rng.uniform() * total;
    double run = 0.0;
    chosen = n - 1;
    for (std::size_t i = 0; i < n; ++i) {
      run += d2[i];
      if (u < run && d2[i] > 0.0) {
        chosen = i;
        break;
      }
    }
  }
  return centres;
}

}  // namespace

Result<KMeansResult, std::string> kmeans(std::span<const float> rows, std::size_t dims,
                                         const KMeansParams& params) {
  if (params.k == 0) return err(std::string("k-means: k must be at least 1"));
  if (dims == 0 || rows.size() % dims != 0)
    return err(std::string("k-means: the pool is not whole rows of a positive length"));
  const std::size_t n = rows.size() / dims;
  if (n < params.k)
    return err("k-means: " + std::to_string(n) + " rows cannot make " + std::to_string(params.k) +
               " clusters");
  for (std::size_t i = 0; i < rows.size(); ++i)
    if (!std::isfinite(rows[i]))
      return err("k-means: row " + std::to_string(i / dims) + " has a value that is not finite");
  const std::size_t k = params.k;
  core::Rng rng(params.seed);
  KMeansResult out;
  out.centres = seed_centres(rows, dims, k, rng);
  out.assignment.assign(n, std::numeric_limits<std::uint32_t>::max());
  std::vector<std::uint32_t> next(n);
  std::vector<double> d2(n);
  std::vector<double> sums(k * dims);
  std::vector<std::size_t> counts(k);
  for (std::uint32_t it = 0; it < params.max_iterations; ++it) {
    assign(rows, dims, out.centres, k, next, d2);
    const bool changed = next != out.assignment;
    out.assignment.swap(next);
    out.iterations = it + 1;
    if (!changed) break;
    // New centres: the means of their rows, summed in row order.
    std::fill(sums.begin(), sums.end(), 0.0);
    std::fill(counts.begin(), counts.end(), 0);
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t c = out.assignment[i];
      ++counts[c];
      for (std::size_t d = 0; d < dims; ++d) sums[c * dims + d] += rows[i * dims + d];
    }
    for (std::size_t c = 0; c < k; ++c) {
      if (counts[c] == 0) {  // empty: the row farthest from its centre (not already moved)
        std::size_t far = 0;
        for (std::size_t i = 1; i < n; ++i)
          if (d2[i] > d2[far]) far = i;
        std::copy_n(rows.data() + far * dims, dims, out.centres.data() + c * dims);
        d2[far] = 0.0;
        continue;
      }
      for (std::size_t d = 0; d < dims; ++d)
        out.centres[c * dims + d] =
            static_cast<float>(sums[c * dims + d] / static_cast<double>(counts[c]));
    }
  }
  assign(rows, dims, out.centres, k, out.assignment, d2);
  out.inertia = 0.0;
  for (const double v : d2) out.inertia += v;
  return out;
}

Result<kernels::VisualDictionary, std::string> build_dictionary(
    std::span<const float> pool, const kernels::SpinFeatureParams& features,
    const KMeansParams& params, std::string provenance) {
  const std::size_t dims = kernels::spin_image_bins(features.spin.image_width);
  if (features.spin.image_width == 0 || features.spin.image_width > kernels::MAX_SPIN_IMAGE_WIDTH)
    return err("dictionary: image width " + std::to_string(features.spin.image_width) +
               " is outside 1.." + std::to_string(kernels::MAX_SPIN_IMAGE_WIDTH));
  if (pool.size() % dims != 0)
    return err("dictionary: the pool is not whole spin images of " + std::to_string(dims) +
               " values");
  std::vector<float> rows;
  rows.reserve(pool.size());
  for (std::size_t at = 0; at < pool.size(); at += dims) {
    const auto r = pool.subspan(at, dims);
    if (std::any_of(r.begin(), r.end(), [](float v) { return v != 0.0F; }))
      rows.insert(rows.end(), r.begin(), r.end());
  }
  auto km = kmeans(rows, dims, params);
  if (!km) return err("dictionary: " + km.error());
  kernels::VisualDictionary d;
  d.words = params.k;
  d.dims = dims;
  d.data.resize(d.words * dims);
  for (std::size_t j = 0; j < d.words; ++j)
    for (std::size_t v = 0; v < dims; ++v) d.data[v * d.words + j] = km->centres[j * dims + v];
  d.spin = features.spin;
  d.keypoint_leaf = features.keypoint_leaf;
  d.normal_radius = features.normal_radius;
  d.id = kernels::dictionary_id(d);
  std::ostringstream p;
  p << provenance << "; k-means seed " << params.seed << ", " << km->iterations << " iterations, "
    << rows.size() / dims << " spin images, inertia " << km->inertia;
  d.provenance = p.str();
  return d;
}

}  // namespace orthoflow::learning
