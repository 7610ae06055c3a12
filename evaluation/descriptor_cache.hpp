#pragma once
/// @file
/// @brief The on-disk descriptor cache of describe_dataset(): one binary file per (dataset,
/// parameter set), entries keyed by a view's relative path, byte size and modification time. A
/// cache is only ever a hint: a missing, truncated or foreign file is ignored and the descriptors
/// are recomputed.
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <unordered_map>
#include <vector>

namespace orthoflow::evaluation {

/// @brief The identity of a view file when it was described.
struct FileStamp {
  std::uint64_t size = 0;
  std::int64_t mtime_ns = 0;
  [[nodiscard]] bool operator==(const FileStamp&) const noexcept = default;
};

/// @brief Reads @p path's size and modification time; false if it cannot be stat'ed.
[[nodiscard]] bool stamp_file(const std::filesystem::path& path, FileStamp& out);

/// @brief Cached descriptors of one parameter set.
struct DescriptorCache {
  struct Entry {
    FileStamp stamp;
    std::vector<float> descriptor;
  };
  std::size_t length = 0;
  std::unordered_map<std::string, Entry> entries;  ///< by relative path
};

/// @brief Parses a cache file's bytes; returns an empty cache (entries empty) for anything
/// malformed or of another descriptor @p length. Bounds-checked on every field (fuzzed by
/// tests/fuzz).
[[nodiscard]] DescriptorCache parse_descriptor_cache(std::span<const char> bytes,
                                                     std::size_t length);
/// @brief The file bytes of @p cache (magic "OFDC", version 1, little-endian host layout).
[[nodiscard]] std::string encode_descriptor_cache(const DescriptorCache& cache);
/// @brief Writes @p cache to @p path through a temporary file and a rename (never a half-written
/// cache).
/// @return an error sentence, empty on success.
[[nodiscard]] std::string save_descriptor_cache(const DescriptorCache& cache,
                                                const std::filesystem::path& path);

}  // namespace orthoflow::evaluation
