#pragma once
/// @file
/// @brief The state behind PerceptualMemory (shared by perceptual_memory.cpp and
/// memory_export.cpp). Internal to learning/.
#include <leveldb/db.h>
#include <leveldb/write_batch.h>

#include <memory>
#include <string>
#include <vector>

#include "learning/detail/memory_codec.hpp"
#include "learning/perceptual_memory.hpp"

namespace orthoflow::learning {

/// @brief One category of the index: its record plus the Bayes accumulator, kept in RAM so that a
/// teach can write the updated model in the same batch as the views.
struct IndexedCategory {
  CategoryId id = NO_CATEGORY;
  CategoryRecord record;
  ModelRecord model;
};

struct PerceptualMemory::State {
  ~State();
  std::filesystem::path dir;
  std::filesystem::path copy;  ///< READ_ONLY on a read-only store: the private copy LevelDB opened
  bool read_only = false;
  MemoryConfig cfg;
  std::unique_ptr<leveldb::DB> db;
  std::unique_ptr<Learner> learner;
  std::vector<IndexedCategory> index;  // by id
  CategoryId next_id = 0;
  std::uint64_t writes = 0;
  std::vector<std::string> warnings;  ///< PerceptualMemory::open_warnings()

  /// @brief Every view of category @p id in sequence order, decoded and checked against params.
  [[nodiscard]] static Result<std::vector<ViewRecord>, MemoryError> read_views(State& s,
                                                                               CategoryId id);

  /// @brief The index entry of @p label, or nullptr.
  [[nodiscard]] IndexedCategory* find(std::string_view label) noexcept {
    for (IndexedCategory& c : index) {
      if (c.record.label == label) { return &c; }
    }
    return nullptr;
  }
};

/// @brief A teach written into a batch but not applied yet: the memory's index and learner change
/// only after the batch's synced write (teach, and import's one batch for every category).
struct StagedTeach {
  IndexedCategory next;
  bool fresh = false;         ///< a new category (next.id taken from the running next id)
  std::vector<float> values;  ///< the views' descriptors, row-major
};

/// @brief Checks @p views, adds their records to @p batch and returns what to apply after the
/// write.
/// @p next_id is the running next category id (advanced for a new category). Nothing else changes.
/// @brief Where staged views come from: a new teach must carry a real view (its descriptor has a
/// non-zero value); an import may restore the all-zero views that stores of earlier releases took.
enum class ViewSource : std::uint8_t { TEACH, IMPORT };
[[nodiscard]] Result<StagedTeach, MemoryError> stage_teach(
    PerceptualMemory::State& s, std::string_view label, std::span<const ViewRecord> views,
    CategoryId& next_id, leveldb::WriteBatch& batch, ViewSource source = ViewSource::TEACH);
/// @brief After the synced write: the index and the learner take the staged teach.
void apply_staged(PerceptualMemory::State& s, const StagedTeach& staged);
/// @brief Writes @p batch synced (READ_ONLY and WRITE_FAILED name @p what).
[[nodiscard]] Result<void, MemoryError> write_synced(PerceptualMemory::State& s,
                                                     leveldb::WriteBatch& batch,
                                                     const std::string& what);

/// @brief The bytes of a LevelDB slice.
[[nodiscard]] inline std::string_view as_view(const leveldb::Slice& s) noexcept {
  return {s.data(), s.size()};
}

/// @brief A MemoryError with "<dir>: <what>".
[[nodiscard]] MemoryError memory_error(MemoryError::Code code, const std::filesystem::path& where,
                                       const std::string& what);

}  // namespace orthoflow::learning
