#pragma once
/// @file
/// @brief Bag of words (thesis chapter 4, the BoW layer): a dictionary of visual words (the centres
/// of k-means clusters of spin images, learning/dictionary.hpp builds it), each spin image of an
/// object view assigned to its nearest word, and the view described by the histogram of its words.
///
/// The nearest word is exact: the SIMD distances() narrow the words down, and every word within
/// their tolerance of the nearest is measured again in double precision in the scalar twin's order
/// (ties: the lower index). So the SIMD path and the twin, and x86 and ARM, pick the same word.
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "kernels/distance.hpp"
#include "kernels/spin_image.hpp"
#include "kernels/topic_model.hpp"

namespace orthoflow::kernels {

/// @brief A dictionary of visual words and how its words were made (the spin images' parameters
/// and keypoints, the normals' radius), so a view is described exactly as the words were.
struct VisualDictionary {
  std::size_t words = 0;        ///< V
  std::size_t dims = 0;         ///< values per word: spin_image_bins(spin.image_width)
  std::vector<float> data;      ///< structure of arrays: value d of word j at data[d * words + j]
  SpinImageParams spin{};       ///< how the pooled spin images were computed
  float keypoint_leaf = 0.01F;  ///< VS, metres: the keypoints' voxel grid
  float normal_radius = 0.02F;  ///< metres: kernels::point_normals' radius
  std::optional<TopicModel> topics;  ///< LDA fitted over the words (the topic layer), if any
  std::uint64_t id = 0;              ///< a hash of all of the above (dictionary_id())
  std::string provenance;  ///< where the pool came from, k-means seed and iterations (free text)

  [[nodiscard]] DescriptorMatrixView view() const noexcept { return {data, dims, words, words}; }
};

/// @brief FNV-1a 64 over the words, dims, every word value's bits and the parameters, and the topic
/// model's parameters and counts when it has one (not the provenance): equal dictionaries have
/// equal ids on every machine.
[[nodiscard]] std::uint64_t dictionary_id(const VisualDictionary& d) noexcept;
/// @brief "3f2a9c0d11e4b7a0": the id as 16 hex digits.
[[nodiscard]] std::string dictionary_id_hex(std::uint64_t id);

/// @brief No word: a feature that is not finite, or an empty dictionary.
inline constexpr std::size_t NO_WORD = std::numeric_limits<std::size_t>::max();

/// @brief The word nearest @p feature (Euclidean). @p scratch holds at least words.count floats.
/// @return its column, or NO_WORD. @note No allocation; thread-safe; equal to the twin always.
[[nodiscard]] std::size_t nearest_word(std::span<const float> feature, DescriptorMatrixView words,
                                       std::span<float> scratch) noexcept;
/// @brief Scalar reference twin: every word in double precision, ties to the lower index.
[[nodiscard]] std::size_t nearest_word_scalar(std::span<const float> feature,
                                              DescriptorMatrixView words) noexcept;

/// @brief The word of every feature row with weight (all-zero rows skipped), in row order, into
/// @p out (room for every row). @return how many were written.
[[nodiscard]] std::size_t assign_words(std::span<const float> features, DescriptorMatrixView words,
                                       std::span<float> scratch,
                                       std::span<std::uint32_t> out) noexcept;

/// @brief How many of @p features (rows of words.dims values, one per spin image; rows that are
/// all zeros, images without weight, are skipped) are nearest each word, into @p counts
/// (words.count bins of whole numbers): the view's words as Local LDA takes them.
/// @return the features counted (the sum of the counts). @pre counts.size() >= words.count,
/// scratch.size() >= words.count, features.size() a multiple of words.dims.
[[nodiscard]] std::size_t word_counts(std::span<const float> features, DescriptorMatrixView words,
                                      std::span<float> scratch, std::span<float> counts) noexcept;

/// @brief The bag of words: word_counts() divided by their sum, so each bin is the share of the
/// counted features nearest that word (the histogram sums to 1). @return the features counted
/// (0: the histogram is all zeros). @pre as word_counts().
[[nodiscard]] std::size_t bag_of_words(std::span<const float> features, DescriptorMatrixView words,
                                       std::span<float> scratch,
                                       std::span<float> histogram) noexcept;

}  // namespace orthoflow::kernels
