#pragma once
/// @file
/// @brief One descriptor specification: the representation's kind, its parameters and its length
/// travel together as one value (STYLE rule 18). The describe node, the learners, the perceptual
/// memory, the evaluation and the CLI ask the specification for the length instead of computing one
/// of their own, and a store records the specification it was written with. Kinds: GOOD, and the
/// bag of words over spin images (BOW, with its dictionary), the topic histogram of LDA (topics
/// shared by every category, fitted with the dictionary), and the word counts Local LDA learns
/// topics from per category.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/result.hpp"
#include "kernels/good.hpp"
#include "kernels/spin_features.hpp"
#include "kernels/spin_set.hpp"
#include "kernels/visual_words.hpp"

namespace orthoflow::kernels {

/// @brief The representation a descriptor is.
enum class DescriptorKind : std::uint8_t {
  GOOD,  ///< the Global Orthographic Object Descriptor: 3 n^2 normalised histogram values
  BOW,   ///< bag of words: the shares of a view's spin images nearest each word of a dictionary
  LDA,   ///< topic histogram: theta of the view's words under the dictionary's topic model
  LOCAL_LDA,  ///< the view's word counts; the learner describes them in each category's topics
  SPIN_SET,   ///< the view's spin images as a set (kernels/spin_set.hpp), compared by D(U, V)
};
/// @brief "good", "bow", "lda", "local-lda" or "spin".
[[nodiscard]] std::string_view to_string(DescriptorKind kind) noexcept;
/// @brief The kind to_string() names @p name, or std::nullopt.
[[nodiscard]] std::optional<DescriptorKind> descriptor_kind(std::string_view name) noexcept;

/// @brief Kind, parameters and length of a descriptor. A plain value; compare with ==.
struct DescriptorSpec {
  DescriptorKind kind = DescriptorKind::GOOD;
  /// Kind GOOD: bins, frame rule and sign threshold (thesis: 15 bins). Kind BOW: the object frame
  /// and box a view reports (the grasp planner's) still come from GOOD with these parameters.
  GoodConfig good{};
  /// Kind BOW: the dictionary, which carries the spin images' parameters (shared, read-only).
  std::shared_ptr<const VisualDictionary> dictionary;
  /// Kind LOCAL_LDA: the topics every category learns (the learner's, not the describer's).
  LocalTopics local_topics{};
  /// Kind SPIN_SET: the spin images' parameters and the most images a set keeps.
  SpinSetParams spin_set{};

  /// @brief A GOOD specification.
  [[nodiscard]] static DescriptorSpec make_good(std::size_t bins,
                                                GoodMode mode = GoodMode::INVARIANT) noexcept;
  /// @brief A bag-of-words specification over @p dictionary.
  [[nodiscard]] static DescriptorSpec make_bow(
      std::shared_ptr<const VisualDictionary> dictionary) noexcept;
  /// @brief A topic specification over @p dictionary's topic model.
  [[nodiscard]] static DescriptorSpec make_lda(
      std::shared_ptr<const VisualDictionary> dictionary) noexcept;
  /// @brief A specification of @p kind (BOW, LDA or LOCAL_LDA with the thesis's topics) over
  /// @p dictionary.
  [[nodiscard]] static DescriptorSpec over_dictionary(
      DescriptorKind kind, std::shared_ptr<const VisualDictionary> dictionary) noexcept;
  /// @brief Word counts over @p dictionary, for Local LDA with @p topics per category.
  [[nodiscard]] static DescriptorSpec make_local_lda(
      std::shared_ptr<const VisualDictionary> dictionary, const LocalTopics& topics = {}) noexcept;
  /// @brief A set of spin images (the thesis's instance-based approaches I and II).
  [[nodiscard]] static DescriptorSpec make_spin_set(const SpinSetParams& params = {}) noexcept;
  /// @brief BOW, LDA or LOCAL_LDA: described through a dictionary's words.
  [[nodiscard]] bool local() const noexcept {
    return kind == DescriptorKind::BOW || kind == DescriptorKind::LDA ||
           kind == DescriptorKind::LOCAL_LDA;
  }
  /// @brief Described from spin features: the local kinds and SPIN_SET.
  [[nodiscard]] bool spin_features() const noexcept {
    return local() || kind == DescriptorKind::SPIN_SET;
  }
  /// @brief Values per descriptor (GOOD: 3 n^2; BOW and LOCAL_LDA: the dictionary's words; LDA:
  /// its topics; SPIN_SET: spin_set.length()).
  [[nodiscard]] std::size_t length() const noexcept;
  /// @brief Every value is a non-negative share or count, what a naive Bayes learner needs: every
  /// kind but SPIN_SET.
  [[nodiscard]] bool histogram() const noexcept;
  /// @brief Checks the parameters (bins in 1..GOOD_MAX_BINS, a finite non-negative threshold; BOW:
  /// a dictionary with words whose length fits its spin images, finite positive leaf and radius).
  [[nodiscard]] Result<void, std::string> validate() const;
  /// @brief "good bins=15 mode=invariant threshold=0.015", "bow words=70 iw=4 sl=0.05 vs=0.01
  /// nr=0.02 dictionary=3f2a9c0d11e4b7a0", "local-lda topics=30 alpha=1 beta=0.1 iterations=30
  /// seed=1 words=90 ...": what a mismatch error names.
  [[nodiscard]] std::string describe() const;
  /// @brief Same kind and parameters (GOOD: the effective threshold, so unset equals the mode's
  /// default; BOW: the same dictionary id and GOOD parameters).
  [[nodiscard]] bool operator==(const DescriptorSpec& other) const noexcept;
};

/// @brief Everything describing one object view reports besides the values.
struct DescriptorInfo {
  std::size_t length = 0;         ///< values written
  std::array<float, 16> frame{};  ///< world -> object transform, row-major (GoodResult::frame)
  std::array<float, 3> bbox{};    ///< object-frame box edges (GoodResult::bbox)
  std::uint32_t flags = 0;        ///< GoodResult::flags
};

/// @brief The working memory of describing one view over a dictionary: its spin features, and for
/// LDA its words and the topic sampler's scratch. Reserved once, describers that never run at once
/// can share it and describe without allocating (the graph keeps a pool of them).
struct WordScratch {
  SpinFeatures features;
  std::vector<std::uint32_t> words;  ///< LDA: the view's words
  TopicScratch topics;               ///< LDA: the temporary copy of the topic counts
  /// @brief Sizes it for views of up to @p max_points points under @p spec (GOOD: nothing).
  /// @throws std::bad_alloc.
  void reserve(const DescriptorSpec& spec, std::size_t max_points);
};

/// @brief Describes object views under one specification; owns its scratch (sized once).
/// @note Not thread-safe: one describer per thread (or per concurrent object).
class Describer {
 public:
  /// @pre spec.validate() succeeded.
  explicit Describer(const DescriptorSpec& spec);
  [[nodiscard]] const DescriptorSpec& spec() const noexcept { return spec_; }
  /// @brief Writes the descriptor of @p points to the front of @p out. @pre out.size() >=
  /// spec().length(). GOOD: allocation-free. BOW: allocation-free once a view of as many points
  /// has been described (its scratch grows to the largest view). Deterministic (SIMD tolerance as
  /// compute_good(); the words are exact, kernels/visual_words.hpp).
  [[nodiscard]] Result<DescriptorInfo, GoodError> describe(PointsView points,
                                                           std::span<float> out) noexcept;
  /// @brief describe() with the scratch given by the caller (GOOD ignores it): describers that
  /// never run at once may share one (the graph keeps one per worker, each reserved once, so that
  /// describing allocates nothing). A scratch too small for a view grows (it may allocate).
  [[nodiscard]] Result<DescriptorInfo, GoodError> describe(PointsView points, std::span<float> out,
                                                           WordScratch& scratch) noexcept;
  /// @brief BOW: the spin images counted in the last describe() (0 for GOOD).
  [[nodiscard]] std::size_t features() const noexcept { return features_; }

 private:
  /// Over the dictionary: the view's spin features, then their words (and for LDA its topics).
  [[nodiscard]] Result<void, GoodError> describe_words(PointsView points, std::span<float> out,
                                                       WordScratch& scratch);

  DescriptorSpec spec_;
  GoodScratch good_scratch_;
  std::vector<float> good_values_;  ///< BOW: GOOD's values, for its frame and box only
  WordScratch own_;                 ///< describe() without a scratch: grows to the largest view
  std::vector<float> word_scratch_;
  std::size_t features_ = 0;
};

}  // namespace orthoflow::kernels
