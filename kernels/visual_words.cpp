#include "kernels/visual_words.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>

#include "core/assert.hpp"
#include "core/fnv.hpp"

namespace orthoflow::kernels {

namespace {

// The basis dictionary ids have been made with since the first dictionary file (not FNV-1a's own,
// core::FNV_OFFSET: a digit short); kept so that stored ids stay valid.
constexpr std::uint64_t ID_BASIS = 1469598103934665603ULL;

void mix(std::uint64_t& h, std::uint64_t v) noexcept { h = core::fnv1a_value(h, v); }

/// The exact squared distance of the twin: double, in dimension order.
double exact_distance(std::span<const float> f, DescriptorMatrixView w, std::size_t j) noexcept {
  double sum = 0.0;
  for (std::size_t d = 0; d < w.dims; ++d) {
    const double diff = static_cast<double>(f[d]) - static_cast<double>(w.data[d * w.stride + j]);
    sum += diff * diff;
  }
  return sum;
}

bool all_finite(std::span<const float> f) noexcept {
  return std::all_of(f.begin(), f.end(), [](float v) { return std::isfinite(v); });
}

}  // namespace

std::uint64_t dictionary_id(const VisualDictionary& d) noexcept {
  std::uint64_t h = ID_BASIS;
  mix(h, d.words);
  mix(h, d.dims);
  for (const float v : d.data) mix(h, std::bit_cast<std::uint32_t>(v));
  mix(h, d.spin.image_width);
  mix(h, std::bit_cast<std::uint32_t>(d.spin.support_length));
  mix(h, std::bit_cast<std::uint32_t>(d.spin.support_angle_cos));
  mix(h, std::bit_cast<std::uint32_t>(d.keypoint_leaf));
  mix(h, std::bit_cast<std::uint32_t>(d.normal_radius));
  if (d.topics) {
    const TopicModel& t = *d.topics;
    mix(h, t.topics);
    mix(h, std::bit_cast<std::uint64_t>(t.alpha));
    mix(h, std::bit_cast<std::uint64_t>(t.beta));
    mix(h, t.iterations);
    mix(h, t.seed);
    for (const std::uint32_t n : t.word_topic) mix(h, n);
  }
  return h;
}

std::string dictionary_id_hex(std::uint64_t id) {
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(id));
  return text;
}

std::size_t nearest_word_scalar(std::span<const float> feature,
                                DescriptorMatrixView words) noexcept {
  OF_ENFORCE(feature.size() == words.dims, "nearest_word: the feature is not of the words' length");
  if (words.count == 0 || !all_finite(feature)) return NO_WORD;
  std::size_t best = 0;
  double best_d = exact_distance(feature, words, 0);
  for (std::size_t j = 1; j < words.count; ++j) {
    const double d = exact_distance(feature, words, j);
    if (d < best_d) {
      best_d = d;
      best = j;
    }
  }
  return best;
}

std::size_t nearest_word(std::span<const float> feature, DescriptorMatrixView words,
                         std::span<float> scratch) noexcept {
  OF_ENFORCE(feature.size() == words.dims, "nearest_word: the feature is not of the words' length");
  OF_ENFORCE(scratch.size() >= words.count, "nearest_word: scratch shorter than the dictionary");
  if (words.count == 0 || !all_finite(feature)) return NO_WORD;
  distances(feature, words, Metric::L2_SQUARED, scratch);
  float lowest = scratch[0];
  for (std::size_t j = 1; j < words.count; ++j) lowest = std::min(lowest, scratch[j]);
  // distances() is within 1e-5 relative of the twin's float sums; the twin's float sums are within
  // a few ulps of the double ones. Every word the SIMD pass cannot tell from the nearest is
  // measured again exactly; 1e-4 relative and an absolute floor leave room for both.
  const double bound = static_cast<double>(lowest) * (1.0 + 1e-4) + 1e-9;
  std::size_t best = NO_WORD;
  double best_d = 0.0;
  for (std::size_t j = 0; j < words.count; ++j) {
    if (static_cast<double>(scratch[j]) > bound) continue;
    const double d = exact_distance(feature, words, j);
    if (best == NO_WORD || d < best_d) {
      best_d = d;
      best = j;
    }
  }
  return best;
}

std::size_t assign_words(std::span<const float> features, DescriptorMatrixView words,
                         std::span<float> scratch, std::span<std::uint32_t> out) noexcept {
  OF_ENFORCE(words.dims > 0 && features.size() % words.dims == 0,
             "assign_words: the features are not whole rows");
  OF_ENFORCE(out.size() >= features.size() / words.dims, "assign_words: the output is too short");
  std::size_t n = 0;
  for (std::size_t at = 0; at < features.size(); at += words.dims) {
    const auto f = features.subspan(at, words.dims);
    if (std::all_of(f.begin(), f.end(), [](float v) { return v == 0.0F; })) continue;
    const std::size_t w = nearest_word(f, words, scratch);
    if (w != NO_WORD) out[n++] = static_cast<std::uint32_t>(w);
  }
  return n;
}

std::size_t word_counts(std::span<const float> features, DescriptorMatrixView words,
                        std::span<float> scratch, std::span<float> counts) noexcept {
  OF_ENFORCE(words.dims > 0 && features.size() % words.dims == 0,
             "word_counts: the features are not whole rows");
  OF_ENFORCE(counts.size() >= words.count, "word_counts: the histogram is too short");
  std::fill_n(counts.begin(), words.count, 0.0F);
  std::size_t counted = 0;
  for (std::size_t at = 0; at < features.size(); at += words.dims) {
    const auto f = features.subspan(at, words.dims);
    if (std::all_of(f.begin(), f.end(), [](float v) { return v == 0.0F; })) continue;
    const std::size_t w = nearest_word(f, words, scratch);
    if (w == NO_WORD) continue;
    counts[w] += 1.0F;
    ++counted;
  }
  return counted;
}

std::size_t bag_of_words(std::span<const float> features, DescriptorMatrixView words,
                         std::span<float> scratch, std::span<float> histogram) noexcept {
  const std::size_t counted = word_counts(features, words, scratch, histogram);
  if (counted > 0) {
    const float inv = 1.0F / static_cast<float>(counted);
    for (std::size_t j = 0; j < words.count; ++j) histogram[j] *= inv;
  }
  return counted;
}

}  // namespace orthoflow::kernels
