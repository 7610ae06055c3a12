#pragma once
/// @file
/// @brief The perceptual memory (PIPELINE.md section 8): object views, descriptors and category
/// models in LevelDB, durable across restarts and crashes, loaded into a Learner at start-up for
/// recognition. Durability: teach/correct/forget write ONE leveldb::WriteBatch with sync=true and
/// update the learner only after the write returned, so an acknowledged call is on disk and a crash
/// leaves either all of a call or none of it. Schema and export format: docs/LEARNING.md.
#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "kernels/descriptor_spec.hpp"
#include "learning/bayes_learner.hpp"
#include "learning/instance_learner.hpp"
#include "learning/learner_choice.hpp"

namespace orthoflow::learning {

/// @brief Store schema version written under the schema key and in the first export line.
inline constexpr std::uint32_t MEMORY_SCHEMA_VERSION = 1;

/// @brief Plain configuration of a memory.
struct MemoryConfig {
  kernels::DescriptorSpec
      descriptor;  ///< representation; must match the store's (kind and parameters)
  LearnerKind learner = LearnerKind::INSTANCE;
  InstanceConfig instance;  ///< descriptor_length is overwritten with descriptor.length()
  BayesConfig bayes;        ///< descriptor_length is overwritten with descriptor.length()
};

/// @brief One object view as stored: descriptor plus where and when it was seen.
struct ViewRecord {
  std::vector<float> descriptor;  ///< MemoryConfig::descriptor.length() values
  std::array<float, 16> frame{};  ///< world -> object transform, row-major (GoodResult::frame)
  std::array<float, 3> bbox{};    ///< object-frame box edges (GoodResult::bbox)
  std::uint64_t track_id = 0;     ///< source track (0 = none)
  std::int64_t stamp_ns = 0;      ///< capture time, ns
};

/// @brief What went wrong, and where.
struct MemoryError {
  enum class Code : std::uint8_t {
    OPEN_FAILED,      ///< LevelDB could not open or create the directory (locked, permissions, ...)
    PARAMS_MISMATCH,  ///< the store was created with other descriptor parameters
    CORRUPT,          ///< a record does not decode (or LevelDB reports corruption)
    WRITE_FAILED,     ///< the synced write failed: nothing was acknowledged
    REJECTED,  ///< the learner refused the input (bad label or descriptor): nothing was written
    UNKNOWN_LABEL,  ///< forget of a label that is not stored
    FILE_FAILED,    ///< an export/import file could not be opened, read or written
    BAD_IMPORT,     ///< an import line is malformed or its parameters differ from the store's
    READ_ONLY,      ///< a write to a store opened with OpenMode::READ_ONLY: nothing was written
  };
  Code code = Code::CORRUPT;
  std::string
      message;  ///< what and where, e.g. "db/: view 3/17: descriptor has 74 values, expected 75"
  /// @brief "<code name>: <message>".
  [[nodiscard]] std::string to_string() const;
};
/// @brief The enumerator's name in lower case, e.g. "params_mismatch".
[[nodiscard]] const char* to_string(MemoryError::Code code) noexcept;

/// @brief A stored category as list() reports it.
struct CategoryEntry {
  CategoryId id = NO_CATEGORY;
  std::string label;
  std::size_t views = 0;
};

/// @brief Totals of a memory.
struct MemoryStats {
  std::size_t categories = 0;
  std::size_t views = 0;
  std::uint64_t writes = 0;  ///< synced batches written since open
  LearnerStats learner;
};

/// @brief A LevelDB-backed perceptual memory and the learner it feeds. Move-only.
/// @note Writers (teach, correct, forget, import_from) must be serialised by the caller (one writer
/// thread, e.g. a graph node with concurrency 1); learner().ask() may run on any thread at any
/// time.
/// @brief How a store is opened. Whatever the mode, a directory that is not an orthoflow store
/// (other files, LevelDB files without CURRENT, a LevelDB database without the schema key) is
/// refused and left untouched.
enum class OpenMode : std::uint8_t {
  READ_ONLY,   ///< the store must exist; every write is refused (READ_ONLY). A store on a read-only
               ///< mount or without write permission is read from a private copy (LevelDB may fold
               ///< its log into a table when it opens a writable one)
  READ_WRITE,  ///< the store must exist
  CREATE,      ///< READ_WRITE, and a store is created when the directory is absent or empty
};

class PerceptualMemory {
 public:
  /// @brief Opens the store at @p dir (see OpenMode) and loads every category into the learner.
  /// Errors: OPEN_FAILED (no store, not a store, in use, unreadable), PARAMS_MISMATCH (message
  /// names both specifications), CORRUPT.
  [[nodiscard]] static Result<PerceptualMemory, MemoryError> open(const std::filesystem::path& dir,
                                                                  const MemoryConfig& cfg,
                                                                  OpenMode mode = OpenMode::CREATE);
  PerceptualMemory(PerceptualMemory&&) noexcept;
  PerceptualMemory& operator=(PerceptualMemory&&) noexcept;
  ~PerceptualMemory();

  /// @brief Stores @p views under @p label (new category if needed), synced, then teaches the
  /// learner.
  /// @return the category id. Errors: REJECTED (nothing written), WRITE_FAILED (nothing
  /// acknowledged).
  [[nodiscard]] Result<CategoryId, MemoryError> teach(std::string_view label,
                                                      std::span<const ViewRecord> views);
  /// @brief Stores one view after a wrong answer; same as teach() with one view.
  [[nodiscard]] Result<CategoryId, MemoryError> correct(std::string_view label,
                                                        const ViewRecord& view);
  /// @brief Deletes a category, its views and its model, synced. Errors: UNKNOWN_LABEL,
  /// WRITE_FAILED.
  [[nodiscard]] Result<void, MemoryError> forget(std::string_view label);
  /// @brief Undoes a teach or correct: deletes the last views.count() stored views of @p label,
  /// which must hold exactly @p views' descriptors in teaching order, and takes them out of the
  /// model, in one synced batch; a category left with no view is deleted. Then the learner
  /// retracts them. Errors: UNKNOWN_LABEL, REJECTED (not its last views, or a bad batch: nothing
  /// written), WRITE_FAILED.
  [[nodiscard]] Result<void, MemoryError> retract(std::string_view label, DescriptorBatch views);
  /// @brief The stored categories by id.
  [[nodiscard]] std::vector<CategoryEntry> list() const;
  [[nodiscard]] MemoryStats stats() const;
  /// @brief The learner to ask(); valid as long as the memory lives. @note ask() is lock-free.
  [[nodiscard]] const Learner& learner() const noexcept;
  /// @brief What opening found wrong and went on from, one sentence each; empty when nothing.
  /// Today: a write-ahead log whose tail is not a whole record (LevelDB drops such a tail quietly,
  /// and it may have been an acknowledged write). A READ_ONLY open of such a store reads a private
  /// copy, so the store keeps the evidence; a writable open replays the log and the tail is gone
  /// after it, so callers must show these warnings.
  [[nodiscard]] const std::vector<std::string>& open_warnings() const noexcept;
  /// @brief The configuration in use (descriptor parameters as stored).
  [[nodiscard]] const MemoryConfig& config() const noexcept;
  /// @brief Every view of category @p id, in teaching order (reads the store; not for the frame
  /// path).
  [[nodiscard]] Result<std::vector<ViewRecord>, MemoryError> views_of(CategoryId id) const;

  /// @brief Writes the whole memory as JSON lines (docs/LEARNING.md) to @p file. @return views
  /// written.
  [[nodiscard]] Result<std::size_t, MemoryError> export_to(const std::filesystem::path& file) const;
  /// @brief Teaches every category of an export file (one synced batch per category). @return views
  /// read. Errors: FILE_FAILED, BAD_IMPORT (line number and reason; nothing after that line is
  /// imported).
  [[nodiscard]] Result<std::size_t, MemoryError> import_from(const std::filesystem::path& file);

  struct State;

 private:
  explicit PerceptualMemory(std::unique_ptr<State> state) noexcept;
  std::unique_ptr<State> state_;
};

}  // namespace orthoflow::learning
