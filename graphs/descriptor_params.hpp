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

/// @brief describe: descriptor (good), bins (1..MAX_GOOD_BINS), mode (invariant|reference),
/// threshold (m). Thesis defaults: GOOD with 15 bins; the invariant frame (docs/GOOD.md).
[[nodiscard]] Result<kernels::DescriptorSpec, std::string> parse_describe_params(
    const engine::ParamMap& params);

/// @brief The specification of the graph's describe node (the default when it has none). Errors
/// name the node.
[[nodiscard]] Result<kernels::DescriptorSpec, std::string> descriptor_of_graph(
    const engine::GraphSpec& spec);

}  // namespace orthoflow::graphs
