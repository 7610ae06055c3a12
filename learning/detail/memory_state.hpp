#pragma once
/// @file
/// @brief The state behind PerceptualMemory (shared by perceptual_memory.cpp and
/// memory_export.cpp). Internal to learning/.
#include <leveldb/db.h>

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

/// @brief The bytes of a LevelDB slice.
[[nodiscard]] inline std::string_view as_view(const leveldb::Slice& s) noexcept {
  return {s.data(), s.size()};
}

/// @brief A MemoryError with "<dir>: <what>".
[[nodiscard]] MemoryError memory_error(MemoryError::Code code, const std::filesystem::path& where,
                                       const std::string& what);

}  // namespace orthoflow::learning
