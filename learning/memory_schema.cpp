// The perceptual memory's schema record (learning/detail/memory_codec.hpp, docs/LEARNING.md): the
// descriptor specification a store was created with, as JSON, written once and checked on every
// open (and in an export's header). The keys and binary records are in memory_codec.cpp.
#include <algorithm>
#include <cmath>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "learning/detail/memory_codec.hpp"

namespace orthoflow::learning {

std::string encode_schema(const kernels::DescriptorSpec& spec) {
  nlohmann::json j{
      {"schema", MEMORY_SCHEMA_VERSION},
      {"descriptor", std::string(kernels::to_string(spec.kind))},
      {"bins", spec.good.bins},
      {"mode", spec.good.mode == kernels::GoodMode::INVARIANT ? "invariant" : "reference"},
      {"threshold", spec.good.effective_threshold()}};
  if (spec.local() && spec.dictionary) {
    const kernels::VisualDictionary& d = *spec.dictionary;
    j["dictionary"] = kernels::dictionary_id_hex(d.id);
    j["words"] = d.words;
    j["image_width"] = d.spin.image_width;
    j["support_length"] = d.spin.support_length;
    j["support_angle_cos"] = d.spin.support_angle_cos;
    j["keypoint_leaf"] = d.keypoint_leaf;
    j["normal_radius"] = d.normal_radius;
  }
  if (spec.kind == kernels::DescriptorKind::SPIN_SET) {
    const kernels::SpinSetParams& p = spec.spin_set;
    j["spin_set"] = {{"max_keypoints", p.max_keypoints},
                     {"image_width", p.features.spin.image_width},
                     {"support_length", p.features.spin.support_length},
                     {"support_angle_cos", p.features.spin.support_angle_cos},
                     {"keypoint_leaf", p.features.keypoint_leaf},
                     {"normal_radius", p.features.normal_radius}};
  }
  if (spec.kind == kernels::DescriptorKind::LOCAL_LDA) {
    const kernels::LocalTopics& t = spec.local_topics;
    j["local_topics"] = {{"topics", t.topics},
                         {"alpha", t.alpha},
                         {"beta", t.beta},
                         {"iterations", t.iterations},
                         {"seed", t.seed}};
  }
  return j.dump();
}

namespace {

/// The dictionary a "bow" schema names (no words), or nullopt with @p why.
std::optional<kernels::VisualDictionary> schema_dictionary(const nlohmann::json& j,
                                                           std::string& why) {
  const auto id = j.find("dictionary");
  const auto words = j.find("words");
  const auto width = j.find("image_width");
  const char* const numbers[] = {"support_length", "support_angle_cos", "keypoint_leaf",
                                 "normal_radius"};
  bool ok = id != j.end() && id->is_string() && id->get<std::string>().size() == 16 &&
            words != j.end() && words->is_number_unsigned() && width != j.end() &&
            width->is_number_unsigned();
  for (const char* n : numbers) ok = ok && j.contains(n) && j[n].is_number();
  std::uint64_t value = 0;
  if (ok) {
    const std::string hex = id->get<std::string>();
    for (const char c : hex) {
      const int digit = c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10 : -1;
      if (digit < 0) ok = false;
      value = (value << 4U) | static_cast<std::uint64_t>(digit < 0 ? 0 : digit);
    }
  }
  if (!ok) {
    why =
        "a \"bow\" schema needs \"dictionary\" (16 hex digits), unsigned \"words\" and "
        "\"image_width\", and numbers \"support_length\", \"support_angle_cos\", "
        "\"keypoint_leaf\", \"normal_radius\"";
    return std::nullopt;
  }
  for (const char* n : numbers) {
    const double v = j[n].get<double>();
    if (!std::isfinite(v) || std::abs(v) > 1e30) {  // a float of the specification
      why = std::string("\"") + n + "\" is not a finite number";
      return std::nullopt;
    }
  }
  if (width->get<std::uint64_t>() > kernels::MAX_SPIN_IMAGE_WIDTH) {
    why = "\"image_width\" is more than " + std::to_string(kernels::MAX_SPIN_IMAGE_WIDTH);
    return std::nullopt;
  }
  kernels::VisualDictionary d;
  d.id = value;
  d.words = words->get<std::size_t>();
  d.spin.image_width = width->get<std::uint32_t>();
  d.dims = kernels::spin_image_bins(d.spin.image_width);
  d.spin.support_length = j["support_length"].get<float>();
  d.spin.support_angle_cos = j["support_angle_cos"].get<float>();
  d.keypoint_leaf = j["keypoint_leaf"].get<float>();
  d.normal_radius = j["normal_radius"].get<float>();
  return d;
}

/// The topics a "local-lda" schema names, or false with @p why.
bool schema_local_topics(const nlohmann::json& j, kernels::LocalTopics& t, std::string& why) {
  const auto o = j.find("local_topics");
  const bool ok = o != j.end() && o->is_object() && o->contains("topics") &&
                  (*o)["topics"].is_number_unsigned() && o->contains("alpha") &&
                  (*o)["alpha"].is_number() && o->contains("beta") && (*o)["beta"].is_number() &&
                  o->contains("iterations") && (*o)["iterations"].is_number_unsigned() &&
                  o->contains("seed") && (*o)["seed"].is_number_unsigned();
  if (!ok) {
    why =
        "a \"local-lda\" schema needs \"local_topics\" with unsigned \"topics\", "
        "\"iterations\" and \"seed\", and numbers \"alpha\" and \"beta\"";
    return false;
  }
  t.topics = (*o)["topics"].get<std::size_t>();
  t.alpha = (*o)["alpha"].get<double>();
  t.beta = (*o)["beta"].get<double>();
  const auto sweeps = (*o)["iterations"].get<std::uint64_t>();
  t.iterations = static_cast<std::uint32_t>(std::min<std::uint64_t>(sweeps, UINT32_MAX));
  t.seed = (*o)["seed"].get<std::uint64_t>();
  // The learner's preconditions: a store never hands it others.
  if (!t.valid()) {  // sweeps past UINT32_MAX were clamped to it, past the limit too
    why = "\"local_topics\" out of range: 1.." + std::to_string(kernels::MAX_LOCAL_TOPICS) +
          " topics, finite alpha and beta > 0, at most " +
          std::to_string(kernels::MAX_GIBBS_SWEEPS) + " iterations";
    return false;
  }
  return true;
}

/// The set a "spin" schema names, or false with @p why.
bool schema_spin_set(const nlohmann::json& j, kernels::SpinSetParams& p, std::string& why) {
  const auto o = j.find("spin_set");
  bool ok = o != j.end() && o->is_object();
  for (const char* n : {"max_keypoints", "image_width"})
    ok = ok && o->contains(n) && (*o)[n].is_number_unsigned();
  for (const char* n : {"support_length", "support_angle_cos", "keypoint_leaf", "normal_radius"})
    ok = ok && o->contains(n) && (*o)[n].is_number();
  if (!ok) {
    why =
        "a \"spin\" schema needs \"spin_set\" with unsigned \"max_keypoints\" and "
        "\"image_width\", and numbers \"support_length\", \"support_angle_cos\", "
        "\"keypoint_leaf\" and \"normal_radius\"";
    return false;
  }
  const auto clamp = [](std::uint64_t v) {
    return static_cast<std::uint32_t>(std::min<std::uint64_t>(v, UINT32_MAX));
  };
  p.max_keypoints = clamp((*o)["max_keypoints"].get<std::uint64_t>());
  p.features.spin.image_width = clamp((*o)["image_width"].get<std::uint64_t>());
  p.features.spin.support_length = (*o)["support_length"].get<float>();
  p.features.spin.support_angle_cos = (*o)["support_angle_cos"].get<float>();
  p.features.keypoint_leaf = (*o)["keypoint_leaf"].get<float>();
  p.features.normal_radius = (*o)["normal_radius"].get<float>();
  if (!p.valid()) {  // the learner's preconditions: a store never hands it others
    why = "\"spin_set\" out of range: image width 1.." +
          std::to_string(kernels::MAX_SPIN_IMAGE_WIDTH) + ", 1.." +
          std::to_string(kernels::MAX_SET_KEYPOINTS) +
          " keypoints, lengths finite and > 0, the support angle's cosine in [0, 1]";
    return false;
  }
  return true;
}

}  // namespace

std::optional<kernels::DescriptorSpec> decode_schema(std::string_view json, std::uint32_t& version,
                                                     std::string& why) {
  const nlohmann::json j = nlohmann::json::parse(json, nullptr, false);
  if (j.is_discarded() || !j.is_object()) {
    why = "not a JSON object";
    return std::nullopt;
  }
  const auto schema = j.find("schema");
  const auto kind = j.find("descriptor");
  const auto bins = j.find("bins");
  const auto mode = j.find("mode");
  const auto threshold = j.find("threshold");
  if (schema == j.end() || !schema->is_number_unsigned() || bins == j.end() ||
      !bins->is_number_unsigned() || mode == j.end() || !mode->is_string() ||
      threshold == j.end() || !threshold->is_number() || (kind != j.end() && !kind->is_string())) {
    why =
        "needs unsigned \"schema\" and \"bins\", string \"mode\", number \"threshold\" (and a "
        "string \"descriptor\")";
    return std::nullopt;
  }
  const std::string kind_name = kind != j.end() ? kind->get<std::string>() : "good";
  const auto named = kernels::descriptor_kind(kind_name);
  if (!named) {
    why = "descriptor \"" + kind_name +
          "\" is not one this build knows (good, bow, lda, local-lda, spin)";
    return std::nullopt;
  }
  kernels::SpinSetParams set;
  const bool set_kind = named == kernels::DescriptorKind::SPIN_SET;
  if (set_kind && !schema_spin_set(j, set, why)) return std::nullopt;
  std::optional<kernels::VisualDictionary> dictionary;
  const bool local_lda = named == kernels::DescriptorKind::LOCAL_LDA;
  const bool over_words = named != kernels::DescriptorKind::GOOD && !set_kind;
  if (over_words && !(dictionary = schema_dictionary(j, why))) return std::nullopt;
  kernels::LocalTopics topics;
  if (local_lda && !schema_local_topics(j, topics, why)) return std::nullopt;
  const std::string m = mode->get<std::string>();
  if (m != "invariant" && m != "reference") {
    why = "mode must be \"invariant\" or \"reference\", not \"" + m + "\"";
    return std::nullopt;
  }
  const double t = threshold->get<double>();
  if (bins->get<std::uint64_t>() == 0 || bins->get<std::uint64_t>() > kernels::GOOD_MAX_BINS ||
      !(t >= 0.0) || t > 1e30) {
    why = "bins must be 1.." + std::to_string(kernels::GOOD_MAX_BINS) +
          " and the threshold a finite number >= 0";
    return std::nullopt;
  }
  version =
      static_cast<std::uint32_t>(std::min<std::uint64_t>(schema->get<std::uint64_t>(), UINT32_MAX));
  auto spec = kernels::DescriptorSpec::make_good(
      bins->get<std::size_t>(),
      m == "invariant" ? kernels::GoodMode::INVARIANT : kernels::GoodMode::REFERENCE);
  spec.good.threshold = threshold->get<float>();
  if (set_kind) {
    spec.kind = *named;
    spec.spin_set = set;
  }
  if (dictionary) {
    spec.kind = *named;
    spec.local_topics = topics;
    spec.dictionary = std::make_shared<const kernels::VisualDictionary>(std::move(*dictionary));
  }
  return spec;
}

}  // namespace orthoflow::learning
