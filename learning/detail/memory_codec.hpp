#pragma once
/// @file
/// @brief LevelDB keys and binary values of the perceptual memory (schema 1, docs/LEARNING.md).
/// Keys sort by kind, then category id (big-endian), then view sequence (big-endian):
///   "s"                     schema JSON
///   {"schema":1,"descriptor":"good","bins":n,"mode":"invariant","threshold":t} "n" next category
///   id (u32) "c" id                  category: u64 next view sequence, u32 live views, label bytes
///   "m" id                  Bayes model: u64 N_k, u32 length, length x f64 sums of descriptors
///   "v" id seq              view: see encode_view()
///   "i" digest (16 hex)     an imported export file (FNV-1a of its lines): a second import is
///   refused
/// Values are little-endian. Internal to learning/.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "kernels/descriptor_spec.hpp"
#include "learning/perceptual_memory.hpp"

namespace orthoflow::learning {

inline constexpr std::string_view KEY_SCHEMA = "s";
inline constexpr std::string_view KEY_NEXT_ID = "n";
/// A bag-of-words store's dictionary (learning/dictionary.hpp's file bytes), written with its
/// schema.
inline constexpr std::string_view KEY_DICTIONARY = "d";
inline constexpr char KIND_CATEGORY = 'c';
inline constexpr char KIND_MODEL = 'm';
inline constexpr char KIND_VIEW = 'v';

/// @brief "c"/"m"/"v" + big-endian id: the key of a category record or model, or the prefix of its
/// views.
[[nodiscard]] std::string category_key(char kind, CategoryId id);
/// @brief "v" + id + big-endian seq.
[[nodiscard]] std::string view_key(CategoryId id, std::uint64_t seq);
/// @brief The id in a "c"/"m"/"v" key; nullopt when the key is too short.
[[nodiscard]] std::optional<CategoryId> key_category(std::string_view key) noexcept;

/// @brief The schema JSON of a store written with @p spec:
/// {"schema":1,"descriptor":"good","bins":n, "mode":...,"threshold":t}; a bag-of-words store adds
/// "dictionary" (its id, 16 hex digits), "words", "image_width", "support_length",
/// "support_angle_cos", "keypoint_leaf" and "normal_radius".
[[nodiscard]] std::string encode_schema(const kernels::DescriptorSpec& spec);
/// @brief Parses a schema JSON (also the export header); nullopt with @p why set when malformed. A
/// header without "descriptor" (written before the descriptor specification existed) is a GOOD
/// store. A "bow" schema gives a dictionary with its parameters, id and word count but no words
/// (the store's "d" record, or the dictionary file, holds them): enough to compare and describe.
[[nodiscard]] std::optional<kernels::DescriptorSpec> decode_schema(std::string_view json,
                                                                   std::uint32_t& version,
                                                                   std::string& why);

/// @brief The category record of the memory's index.
struct CategoryRecord {
  std::uint64_t next_seq = 0;
  std::uint32_t views = 0;
  std::string label;
};
[[nodiscard]] std::string encode_category(const CategoryRecord& c);
[[nodiscard]] std::optional<CategoryRecord> decode_category(std::string_view bytes);

/// @brief The Bayes accumulator record: N_k and the sums of the descriptors.
struct ModelRecord {
  std::uint64_t seen = 0;
  std::vector<double> sums;
};
[[nodiscard]] std::string encode_model(const ModelRecord& m);
[[nodiscard]] std::optional<ModelRecord> decode_model(std::string_view bytes);

/// @brief u32 magic "OFV1", u32 bins, u8 mode, f32 threshold, 16 f32 frame, 3 f32 bbox, u64 track
/// id, i64 stamp ns, u32 n, n f32 descriptor.
[[nodiscard]] std::string encode_view(const ViewRecord& v, const kernels::DescriptorSpec& spec);
/// @brief Decodes a view; nullopt with @p why set when the size, magic or parameters are wrong.
[[nodiscard]] std::optional<ViewRecord> decode_view(std::string_view bytes,
                                                    const kernels::DescriptorSpec& expected,
                                                    std::string& why);

/// @brief u32 little-endian.
[[nodiscard]] std::string encode_u32(std::uint32_t v);
[[nodiscard]] std::optional<std::uint32_t> decode_u32(std::string_view bytes) noexcept;

}  // namespace orthoflow::learning
