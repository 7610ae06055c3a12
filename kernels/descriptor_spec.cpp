#include "kernels/descriptor_spec.hpp"

#include <cmath>
#include <cstdio>
#include <new>

namespace orthoflow::kernels {

std::string_view to_string(DescriptorKind kind) noexcept {
  switch (kind) {
    case DescriptorKind::GOOD:
      return "good";
    case DescriptorKind::BOW:
      return "bow";
    case DescriptorKind::LDA:
      return "lda";
    case DescriptorKind::LOCAL_LDA:
      return "local-lda";
    case DescriptorKind::SPIN_SET:
      return "spin";
  }
  return "unknown";
}

std::optional<DescriptorKind> descriptor_kind(std::string_view name) noexcept {
  for (const DescriptorKind k : {DescriptorKind::GOOD, DescriptorKind::BOW, DescriptorKind::LDA,
                                 DescriptorKind::LOCAL_LDA, DescriptorKind::SPIN_SET})
    if (to_string(k) == name) return k;
  return std::nullopt;
}

DescriptorSpec DescriptorSpec::make_good(std::size_t bins, GoodMode mode) noexcept {
  DescriptorSpec s;
  s.good.bins = bins;
  s.good.mode = mode;
  return s;
}

DescriptorSpec DescriptorSpec::over_dictionary(
    DescriptorKind kind, std::shared_ptr<const VisualDictionary> dictionary) noexcept {
  DescriptorSpec s;
  s.kind = kind;
  s.dictionary = std::move(dictionary);
  return s;
}

DescriptorSpec DescriptorSpec::make_bow(
    std::shared_ptr<const VisualDictionary> dictionary) noexcept {
  return over_dictionary(DescriptorKind::BOW, std::move(dictionary));
}

DescriptorSpec DescriptorSpec::make_lda(
    std::shared_ptr<const VisualDictionary> dictionary) noexcept {
  return over_dictionary(DescriptorKind::LDA, std::move(dictionary));
}

DescriptorSpec DescriptorSpec::make_local_lda(std::shared_ptr<const VisualDictionary> dictionary,
                                              const LocalTopics& topics) noexcept {
  DescriptorSpec s = over_dictionary(DescriptorKind::LOCAL_LDA, std::move(dictionary));
  s.local_topics = topics;
  return s;
}

DescriptorSpec DescriptorSpec::make_spin_set(const SpinSetParams& params) noexcept {
  DescriptorSpec s;
  s.kind = DescriptorKind::SPIN_SET;
  s.spin_set = params;
  return s;
}

std::size_t DescriptorSpec::length() const noexcept {
  if (kind == DescriptorKind::SPIN_SET) return spin_set.length();
  if (kind == DescriptorKind::BOW || kind == DescriptorKind::LOCAL_LDA)
    return dictionary ? dictionary->words : 0;
  if (kind == DescriptorKind::LDA)
    return dictionary && dictionary->topics ? dictionary->topics->topics : 0;
  return 3 * good.bins * good.bins;
}

bool DescriptorSpec::histogram() const noexcept { return kind != DescriptorKind::SPIN_SET; }

Result<void, std::string> DescriptorSpec::validate() const {
  if (good.bins == 0 || good.bins > GOOD_MAX_BINS) {
    return err("descriptor " + describe() + ": bins must be 1.." + std::to_string(GOOD_MAX_BINS));
  }
  const float t = good.effective_threshold();
  if (!std::isfinite(t) || t < 0.0F)
    return err("descriptor " + describe() + ": the threshold must be finite and >= 0");
  if (kind == DescriptorKind::SPIN_SET && !spin_set.valid())
    return err("descriptor " + describe() + ": spin images of width 1.." +
               std::to_string(MAX_SPIN_IMAGE_WIDTH) +
               ", support length, keypoint leaf and normal radius finite and > 0, the support " +
               "angle's cosine in [0, 1], and 1.." + std::to_string(MAX_SET_KEYPOINTS) +
               " keypoints");
  if (local()) {
    if (!dictionary) return err(std::string(to_string(kind)) + " descriptor: no dictionary");
    const VisualDictionary& d = *dictionary;
    const std::uint32_t w = d.spin.image_width;
    if (w == 0 || w > MAX_SPIN_IMAGE_WIDTH || d.dims != spin_image_bins(w))
      return err("descriptor " + describe() + ": words of " + std::to_string(d.dims) +
                 " values do not fit spin images of width " + std::to_string(w));
    if (d.words == 0 || d.data.size() != d.words * d.dims)
      return err("descriptor " + describe() + ": the dictionary holds " +
                 std::to_string(d.data.size()) + " values, not words x dims");
    const auto positive = [](float v) { return std::isfinite(v) && v > 0.0F; };
    if (!positive(d.spin.support_length) || !positive(d.keypoint_leaf) ||
        !positive(d.normal_radius) || !(d.spin.support_angle_cos >= 0.0F) ||
        d.spin.support_angle_cos > 1.0F)
      return err("descriptor " + describe() +
                 ": support length, keypoint leaf and normal radius must be finite and > 0, the "
                 "support angle's cosine in [0, 1]");
    if (kind == DescriptorKind::LDA &&
        (!d.topics || d.topics->words != d.words || !d.topics->consistent()))
      return err("descriptor " + describe() +
                 ": the dictionary has no topic model of its words (orthoflow dictionary build "
                 "--topics K)");
    if (kind == DescriptorKind::LOCAL_LDA && !local_topics.valid())
      return err("descriptor " + describe() + ": Local LDA needs 1.." +
                 std::to_string(MAX_LOCAL_TOPICS) + " topics, finite alpha and beta > 0, and at " +
                 "most " + std::to_string(MAX_GIBBS_SWEEPS) + " sweeps");
  }
  return {};
}

std::string DescriptorSpec::describe() const {
  char text[288];
  if (local()) {
    if (!dictionary) return std::string(to_string(kind)) + " (no dictionary)";
    const VisualDictionary& d = *dictionary;
    char topics[128] = "";
    if (kind == DescriptorKind::LDA && d.topics)
      std::snprintf(topics, sizeof topics, "topics=%zu alpha=%g beta=%g iterations=%u ",
                    d.topics->topics, d.topics->alpha, d.topics->beta, d.topics->iterations);
    if (kind == DescriptorKind::LOCAL_LDA)
      std::snprintf(topics, sizeof topics, "topics=%zu alpha=%g beta=%g iterations=%u seed=%llu ",
                    local_topics.topics, local_topics.alpha, local_topics.beta,
                    local_topics.iterations, static_cast<unsigned long long>(local_topics.seed));
    std::snprintf(text, sizeof text, "%s %swords=%zu iw=%u sl=%g vs=%g nr=%g dictionary=%s",
                  std::string(to_string(kind)).c_str(), topics, d.words, d.spin.image_width,
                  static_cast<double>(d.spin.support_length), static_cast<double>(d.keypoint_leaf),
                  static_cast<double>(d.normal_radius), dictionary_id_hex(d.id).c_str());
    return text;
  }
  if (kind == DescriptorKind::SPIN_SET) {
    const SpinFeatureParams& f = spin_set.features;
    std::snprintf(text, sizeof text, "spin keypoints=%u iw=%u sl=%g sa=%g vs=%g nr=%g",
                  spin_set.max_keypoints, f.spin.image_width,
                  static_cast<double>(f.spin.support_length),
                  static_cast<double>(f.spin.support_angle_cos),
                  static_cast<double>(f.keypoint_leaf), static_cast<double>(f.normal_radius));
    return text;
  }
  std::snprintf(text, sizeof text, "%g", static_cast<double>(good.effective_threshold()));
  return std::string(to_string(kind)) + " bins=" + std::to_string(good.bins) +
         " mode=" + (good.mode == GoodMode::INVARIANT ? "invariant" : "reference") +
         " threshold=" + text;
}

bool DescriptorSpec::operator==(const DescriptorSpec& other) const noexcept {
  const bool same_good = good.bins == other.good.bins && good.mode == other.good.mode &&
                         good.effective_threshold() == other.good.effective_threshold();
  if (kind != other.kind || !same_good) return false;
  if (kind == DescriptorKind::SPIN_SET) return spin_set == other.spin_set;
  if (local()) {
    if (!dictionary || !other.dictionary) return dictionary == other.dictionary;
    return dictionary->id == other.dictionary->id && dictionary->words == other.dictionary->words &&
           (kind != DescriptorKind::LOCAL_LDA || local_topics == other.local_topics);
  }
  return true;
}

void WordScratch::reserve(const DescriptorSpec& spec, std::size_t max_points) {
  if (spec.kind == DescriptorKind::SPIN_SET && spec.spin_set.valid())
    features.reserve(max_points, spec.spin_set.features.spin.image_width);
  if (!spec.local() || !spec.dictionary) return;
  const VisualDictionary& d = *spec.dictionary;
  features.reserve(max_points, d.spin.image_width);
  if (spec.kind == DescriptorKind::LDA && d.topics) {
    words.resize(max_points);
    topics = TopicScratch(d.topics->topics, d.words, max_points);
  }
}

Describer::Describer(const DescriptorSpec& spec) : spec_(spec), good_scratch_(spec.good.bins) {
  if (spec_.kind == DescriptorKind::SPIN_SET)
    good_values_.resize(3 * spec_.good.bins * spec_.good.bins);
  if (spec_.local() && spec_.dictionary) {
    good_values_.resize(3 * spec_.good.bins * spec_.good.bins);
    word_scratch_.resize(spec_.dictionary->words);
  }
}

Result<void, GoodError> Describer::describe_words(PointsView points, std::span<float> out,
                                                  WordScratch& scratch) {
  const bool set = spec_.kind == DescriptorKind::SPIN_SET;
  const SpinFeatureParams params =
      set ? spec_.spin_set.features
          : SpinFeatureParams{spec_.dictionary->spin, spec_.dictionary->keypoint_leaf,
                              spec_.dictionary->normal_radius};
  auto computed = scratch.features.compute(points, params);
  if (!computed) {
    switch (computed.error()) {
      case SpinFeatureError::OUT_OF_MEMORY:
        return err(GoodError::OUT_OF_MEMORY);
      case SpinFeatureError::TOO_MANY_POINTS:
        return err(GoodError::TOO_MANY_POINTS);
      default:
        return err(GoodError::KEYPOINTS_FAILED);
    }
  }
  const std::span<const float> images = scratch.features.images();
  if (set) {
    features_ = write_spin_set(images, spec_.spin_set.image_values(), spec_.spin_set.max_keypoints,
                               out.first(spec_.length()));
    if (features_ == 0) return err(GoodError::NO_FEATURES);
    return {};
  }
  const VisualDictionary& d = *spec_.dictionary;
  if (spec_.kind == DescriptorKind::BOW || spec_.kind == DescriptorKind::LOCAL_LDA) {
    features_ = spec_.kind == DescriptorKind::BOW
                    ? bag_of_words(images, d.view(), word_scratch_, out)
                    : word_counts(images, d.view(), word_scratch_, out);
    if (features_ == 0) return err(GoodError::NO_FEATURES);
    return {};
  }
  // LDA: the view's words, then its topics (a scratch not reserved for the view grows).
  const TopicModel& model = *d.topics;
  const std::size_t rows = images.size() / d.dims;
  try {
    if (scratch.words.size() < rows) scratch.words.resize(rows);
    if (scratch.topics.word_topic.size() < model.topics * model.words ||
        scratch.topics.p.size() < model.topics)
      scratch.topics = TopicScratch(model.topics, model.words, rows);
    if (scratch.topics.z.size() < rows) scratch.topics.z.resize(rows);
  } catch (const std::bad_alloc&) { return err(GoodError::OUT_OF_MEMORY); }
  features_ = assign_words(images, d.view(), word_scratch_, scratch.words);
  if (features_ == 0) return err(GoodError::NO_FEATURES);
  if (!infer_topics(std::span<const std::uint32_t>(scratch.words.data(), features_), model,
                    scratch.topics, out))
    return err(GoodError::OUTPUT_TOO_SMALL);
  return {};
}

Result<DescriptorInfo, GoodError> Describer::describe(PointsView points,
                                                      std::span<float> out) noexcept {
  return describe(points, out, own_);
}

Result<DescriptorInfo, GoodError> Describer::describe(PointsView points, std::span<float> out,
                                                      WordScratch& scratch) noexcept {
  features_ = 0;
  if (!spec_.spin_features()) {
    auto good = compute_good(points, spec_.good, good_scratch_, out);
    if (!good) return err(good.error());
    return DescriptorInfo{good->length, good->frame, good->bbox, good->flags};
  }
  if ((spec_.local() && !spec_.dictionary) || out.size() < spec_.length())
    return err(GoodError::OUTPUT_TOO_SMALL);
  // The frame and box come from GOOD (the grasp planner needs them whatever the representation).
  auto good = compute_good(points, spec_.good, good_scratch_, good_values_);
  if (!good) return err(good.error());
  auto words = describe_words(points, out, scratch);
  if (!words) return err(words.error());
  return DescriptorInfo{spec_.length(), good->frame, good->bbox, good->flags};
}

}  // namespace orthoflow::kernels
