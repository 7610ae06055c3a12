#pragma once
/// @file
/// @brief The open-ended learner interface (PIPELINE.md sections 7-8, thesis chapter 5): teach,
/// correct, ask, forget over a set of categories that is never fixed in advance. Concurrency model
/// shared by every Learner: writers (teach, correct, forget, restore) are serialised by an internal
/// mutex and publish an immutable snapshot; ask() reads the current snapshot without any lock
/// (hazard slots, learning/snapshot_cell.hpp), so recognition never waits for learning. A writer
/// returns only after its snapshot is the one the next ask() sees.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "core/fixed_text.hpp"
#include "core/result.hpp"
#include "kernels/topic_model.hpp"

namespace orthoflow::learning {

/// @brief Identifier of a category; assigned at first teach, never reused within one learner or
/// memory.
using CategoryId = std::uint32_t;
/// @brief The category of a Prediction that names none (unknown, or nothing learned yet).
inline constexpr CategoryId NO_CATEGORY = 0xFFFFFFFFU;
/// @brief Longest label in bytes (Label keeps it inline with a terminating zero).
inline constexpr std::size_t LABEL_MAX_BYTES = core::TEXT_MAX_BYTES;

/// @brief A category name stored inline (no allocation), so a Prediction can be copied and kept
/// after the learner changes. Label::from(s) keeps at most LABEL_MAX_BYTES bytes (check with
/// validate_label()).
using Label = core::Text;

/// @brief The answer of Learner::ask().
/// score is the decision value: the NOCD of the best category for InstanceLearner (plain L2
/// distance to the nearest stored view when normalisation is off; lower is better), the
/// log-posterior log P(C_k) + sum_i y_i log P(x_i | C_k) for BayesLearner (higher is better).
struct Prediction {
  bool unknown = true;           ///< no category accepted (nothing learned, or min NOCD > CT)
  Label label;                   ///< best category, even when unknown (empty when nothing learned)
  float score = 0.0F;            ///< decision value of label (see above)
  Label runner_up;               ///< second-best category (empty when fewer than two)
  float runner_up_score = 0.0F;  ///< decision value of runner_up
  CategoryId category = NO_CATEGORY;  ///< id of label, NO_CATEGORY when unknown
  std::uint64_t generation =
      0;  ///< generation of the snapshot that answered (monotone per learner)
};

/// @brief Why a teach, correct, forget or restore was refused. Nothing is changed when one is
/// returned.
enum class LearnError : std::uint8_t {
  EMPTY_LABEL,      ///< the label is ""
  LABEL_TOO_LONG,   ///< the label has more than LABEL_MAX_BYTES bytes
  BAD_CHARACTERS,   ///< not UTF-8 in NFC, or a control, invisible or direction-control character
                    ///< (core/label_text.hpp)
  NO_VIEWS,         ///< the batch holds no view
  WRONG_LENGTH,     ///< a descriptor's length differs from descriptor_length()
  NOT_FINITE,       ///< a descriptor value is NaN or infinite
  NEGATIVE_VALUE,   ///< a histogram value is negative (BayesLearner: histograms only)
  UNKNOWN_LABEL,    ///< forget() of a label that was never taught
  DUPLICATE_ID,     ///< restore() got two categories with one id or one label
  NOT_LAST_VIEWS,   ///< retract(): the views are not the category's last ones (or more than it has)
  NOT_A_SPIN_SET,   ///< SpinSetLearner: not a set descriptor (kernels/spin_set.hpp)
  NOT_WORD_COUNTS,  ///< LocalLdaLearner: a value is not a whole number, or a view has no word or
                    ///< more than max_words
};
/// @brief A sentence saying what was wrong, e.g. "label longer than 63 bytes".
[[nodiscard]] const char* to_string(LearnError error) noexcept;

/// @brief Checks a label with the one label rule (core::check_label): EMPTY_LABEL, LABEL_TOO_LONG
/// or BAD_CHARACTERS, or success.
[[nodiscard]] Result<void, LearnError> validate_label(std::string_view label) noexcept;

/// @brief Several views of one object, row-major: view v is values[v * length .. (v + 1) * length).
struct DescriptorBatch {
  std::span<const float> values;
  std::size_t length = 0;  ///< values per descriptor
  /// @brief Number of views (values.size() / length; 0 when length is 0).
  [[nodiscard]] std::size_t count() const noexcept {
    return length == 0 ? 0 : values.size() / length;
  }
  /// @brief View @p v. @pre v < count()
  [[nodiscard]] std::span<const float> view(std::size_t v) const noexcept {
    return values.subspan(v * length, length);
  }
};

/// @brief Checks every view of a batch against @p length: NO_VIEWS, WRONG_LENGTH, NOT_FINITE,
/// and NEGATIVE_VALUE when @p histograms is set.
[[nodiscard]] Result<void, LearnError> validate_batch(DescriptorBatch views, std::size_t length,
                                                      bool histograms) noexcept;

/// @brief Caller-owned working memory of ask(): a fixed chunk of distances. ask() walks a
/// category's views in chunks of this size, so any size works for any number of stored views
/// (bigger = fewer kernel calls).
/// @note One scratch per thread; allocated once here, never by ask().
class AskScratch {
 public:
  /// @brief Default chunk: 1024 distances (4 KiB).
  static constexpr std::size_t DEFAULT_CHUNK = 1024;
  explicit AskScratch(std::size_t chunk = DEFAULT_CHUNK) : distances_(chunk == 0 ? 1 : chunk) {}
  [[nodiscard]] std::span<float> distances() noexcept { return distances_; }
  /// @brief Grows the chunk to at least @p n distances (Learner::prepare(); allocates).
  void reserve_distances(std::size_t n) {
    if (distances_.size() < n) distances_.resize(n);
  }
  /// @brief Hazard-slot hint (learning/snapshot_cell.hpp): the slot this thread used last.
  std::size_t slot_hint = 0;
  /// @brief LocalLdaLearner: a target's words, its topics in one category and the temporary copy
  /// of that category's counts. Empty until Learner::prepare() sizes them (once, before asking).
  std::vector<std::uint32_t> words;
  std::vector<float> theta;
  kernels::TopicScratch topics;

 private:
  std::vector<float> distances_;
};

/// @brief Counters of a learner's current snapshot.
struct LearnerStats {
  std::size_t categories = 0;
  std::size_t views = 0;  ///< views taught in total over live categories (Bayes: N)
  std::size_t stored_floats =
      0;  ///< floats held by the snapshot (instance: views x length; Bayes: categories x length)
  std::uint64_t generation = 0;  ///< snapshots published so far
  std::size_t retired_pending =
      0;  ///< old snapshots still waiting for a reader to leave (bounded by the slots)
};

/// @brief A category handed to restore(): what the perceptual memory stored for it.
struct RestoredCategory {
  CategoryId id = NO_CATEGORY;
  std::string_view label;
  DescriptorBatch views;                 ///< every stored view (InstanceLearner needs them)
  std::span<const double> accumulators;  ///< sum of the views' descriptors (BayesLearner; may be
                                         ///< empty: then it is recomputed from views)
  std::uint64_t seen = 0;  ///< N_k: views accumulated (BayesLearner, used with accumulators)
};

/// @brief The summary of one category, as listed by categories().
struct CategorySummary {
  CategoryId id = NO_CATEGORY;
  Label label;
  std::size_t views = 0;
  float spread = 0.0F;  ///< InstanceLearner: ICD in use; BayesLearner: 0
};

/// @brief An open-ended category learner. Writers are serialised internally by a mutex; ask() takes
/// no lock: it pins the current snapshot through a hazard slot (it re-reads only if a writer
/// swapped the snapshot in between, and yields only when more than SNAPSHOT_READER_SLOTS threads
/// ask at once).
class Learner {
 public:
  virtual ~Learner() = default;
  Learner() = default;
  Learner(const Learner&) = delete;
  Learner& operator=(const Learner&) = delete;

  /// @brief Adds @p views to category @p label, creating it when new (thesis: teach, C_n = C_{n-1}
  /// U {O_n}).
  /// @return the category id. @note Thread-safe (serialised with other writers); publishes one
  /// snapshot.
  [[nodiscard]] virtual Result<CategoryId, LearnError> teach(std::string_view label,
                                                             DescriptorBatch views) = 0;
  /// @brief Teaches one view after a wrong answer (thesis: correct); same rules as teach().
  [[nodiscard]] Result<CategoryId, LearnError> correct(std::string_view label,
                                                       std::span<const float> view) {
    return teach(label, DescriptorBatch{view, view.size()});
  }
  /// @brief Predicts the category of @p descriptor from the current snapshot.
  /// @pre descriptor.size() == descriptor_length() (else an unknown Prediction with score NaN).
  /// @note No allocation, no lock; thread-safe with one scratch per thread; deterministic for one
  /// snapshot.
  [[nodiscard]] virtual Prediction ask(std::span<const float> descriptor,
                                       AskScratch& scratch) const noexcept = 0;
  /// @brief Sizes @p scratch for ask() once, so that asking allocates nothing (LocalLdaLearner
  /// needs its topic scratch; the others need nothing). Call it on each scratch before its first
  /// ask().
  virtual void prepare(AskScratch& scratch) const { (void)scratch; }
  /// @brief Removes category @p label and all its views. @note Thread-safe; publishes one snapshot.
  [[nodiscard]] virtual Result<void, LearnError> forget(std::string_view label) = 0;
  /// @brief Takes back the last views.count() views taught to @p label (undo of a teach or
  /// correct): @p views must be those views, in teaching order (InstanceLearner compares them
  /// exactly; BayesLearner subtracts them from the accumulators and N_k). A category left with no
  /// view is removed. Errors: UNKNOWN_LABEL, NOT_LAST_VIEWS, and the batch errors of teach().
  /// Nothing changes on an error. @note Thread-safe; publishes one snapshot.
  [[nodiscard]] virtual Result<void, LearnError> retract(std::string_view label,
                                                         DescriptorBatch views) = 0;
  /// @brief Replaces the whole state with @p categories (start-up load). The next new label gets
  /// max(@p next_id, largest restored id + 1), so ids stay in step with the store that assigned
  /// them. Errors: DUPLICATE_ID, and the teach() errors for a bad label or view. @note Publishes
  /// one snapshot.
  [[nodiscard]] virtual Result<void, LearnError> restore(
      std::span<const RestoredCategory> categories, CategoryId next_id) = 0;
  /// @brief Counters of the current snapshot. @note Lock-free like ask().
  [[nodiscard]] virtual LearnerStats stats() const noexcept = 0;
  /// @brief The categories of the current snapshot, by id (allocates: not for the frame path).
  [[nodiscard]] virtual std::vector<CategorySummary> categories() const = 0;
  /// @brief Values per descriptor (3 n^2 for GOOD with n bins).
  [[nodiscard]] virtual std::size_t descriptor_length() const noexcept = 0;
  /// @brief "instance", "bayes", "local-lda-instance", "local-lda-likelihood" or
  /// "local-lda-topic-bayes".
  [[nodiscard]] virtual const char* kind() const noexcept = 0;
};

}  // namespace orthoflow::learning
