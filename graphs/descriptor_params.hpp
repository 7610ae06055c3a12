#pragma once
/// @file
/// @brief The describe node's parameters as the one kernels::DescriptorSpec, so that the describe
/// node, the learner `orthoflow run` opens and the perceptual memory agree on the representation by
/// construction (start-up only: these allocate).
#include <string>

#include "core/result.hpp"
#include "engine/graph.hpp"
#include "engine/params.hpp"
#include "kernels/descriptor_spec.hpp"

namespace orthoflow::graphs {

/// @brief describe: descriptor (good|bow), bins (1..MAX_GOOD_BINS), mode (invariant|reference),
/// threshold (m); bow: dictionary (a file of `orthoflow dictionary build`, loaded here) and
/// max_object_points (the describe node's scratch, parse_max_object_points). Thesis defaults: GOOD
/// with 15 bins; the invariant frame (docs/GOOD.md).
[[nodiscard]] Result<kernels::DescriptorSpec, std::string> parse_describe_params(
    const engine::ParamMap& params);

/// @brief describe's max_object_points (bow: the largest object view it describes; larger ones are
/// left undescribed and counted): default 20000.
[[nodiscard]] Result<std::size_t, std::string> parse_max_object_points(
    const engine::ParamMap& params);

/// @brief The specification of the graph's describe node (the default when it has none). Errors
/// name the node.
[[nodiscard]] Result<kernels::DescriptorSpec, std::string> descriptor_of_graph(
    const engine::GraphSpec& spec);

}  // namespace orthoflow::graphs
