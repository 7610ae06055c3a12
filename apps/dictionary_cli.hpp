#pragma once
/// @file
/// @brief (internal) What the parts of `orthoflow dictionary` share (cmd_dictionary.cpp: the
/// options, build and show; cmd_dictionary_inputs.cpp: the object views and the objects segmented
/// from scene frames that build describes): the inputs and the error exit.
#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "kernels/point_cloud.hpp"

namespace orthoflow::apps::dictionary_cli {

/// @brief Prints "orthoflow dictionary: MESSAGE" on stderr and exits with @p code (throws
/// CLI::RuntimeError). @pre none.
[[noreturn]] void fail(const std::string& message, int code);

/// @brief Every *.pcd under the directories (or the files named), sorted: the pool's order.
/// @pre none (a root that is neither a file nor a directory fails with EXIT_BAD_INPUT).
[[nodiscard]] std::vector<std::filesystem::path> views_under(const std::vector<std::string>& roots);

/// @brief The objects the product's segmentation (the graph's preprocess, table and objects nodes)
/// finds in every frame under @p roots, in frame order and candidate order: their finite points.
/// @p frames: how many frames were read. @pre none (unreadable frames fail with EXIT_BAD_INPUT).
/// Deterministic: the same frames give the same objects.
[[nodiscard]] std::vector<kernels::PointCloud> objects_in_scenes(
    const std::vector<std::string>& roots, const std::string& graph, std::size_t& frames);

}  // namespace orthoflow::apps::dictionary_cli
