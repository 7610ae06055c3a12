#pragma once
/// @file
/// @brief What a perceptual-memory directory holds before LevelDB touches it, so that opening a
/// store never creates one where it must not and never "repairs" a damaged or foreign directory
/// into an empty store (LevelDB's create_if_missing deletes the table files of a store whose
/// CURRENT is gone). Internal to learning/.
#include <filesystem>
#include <string>

#include "core/result.hpp"
#include "learning/perceptual_memory.hpp"

namespace orthoflow::learning {

/// @brief The state of a store directory.
enum class StoreDir {
  ABSENT,   ///< nothing at the path
  EMPTY,    ///< an empty directory
  STORE,    ///< a LevelDB database (CURRENT present)
  DAMAGED,  ///< LevelDB files (MANIFEST-*, *.ldb, *.log) but no CURRENT
  FOREIGN,  ///< a directory of other files, or a file
};

/// @brief Inspects @p dir without changing anything.
[[nodiscard]] StoreDir inspect_store_dir(const std::filesystem::path& dir);

/// @brief True if this process may create files in @p dir (access(2) W_OK: a read-only mount or a
/// directory without write permission is not writable, also for root on a read-only mount).
[[nodiscard]] bool writable_dir(const std::filesystem::path& dir) noexcept;

/// @brief Copies the regular files of the store @p dir (without LOCK) into a fresh private
/// directory and returns it: a read-only store is read from the copy, which LevelDB may write.
[[nodiscard]] Result<std::filesystem::path, MemoryError> private_copy(
    const std::filesystem::path& dir);

/// @brief True if @p file would be written inside the store @p dir (export into the store).
[[nodiscard]] bool inside_store(const std::filesystem::path& file,
                                const std::filesystem::path& dir);

}  // namespace orthoflow::learning
