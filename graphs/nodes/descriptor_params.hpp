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

/// @brief describe: descriptor (good|spin|bow|lda|local-lda), bins (1..MAX_GOOD_BINS), mode
/// (invariant|reference), threshold (m); spin: spin_keypoints, spin_width, spin_support (m),
/// spin_leaf (m) (kernels::SpinSetParams, the thesis's sets by default); bow, lda, local-lda:
/// dictionary (a file of `orthoflow dictionary build`, loaded here), local_topics; spin and the
/// dictionary's kinds: max_object_points (the describe node's scratch, parse_max_object_points).
/// Thesis defaults: GOOD with 15 bins; the invariant frame (docs/GOOD.md).
[[nodiscard]] Result<kernels::DescriptorSpec, std::string> parse_describe_params(
    const engine::ParamMap& params);

/// @brief describe's max_object_points (bow: the largest object view it describes; larger ones are
/// left undescribed and counted): default 20000.
[[nodiscard]] Result<std::size_t, std::string> parse_max_object_points(
    const engine::ParamMap& params);

/// @brief Descriptor floats per object the frame blocks of @p graph need
/// (descriptor_room_for(length)): a set of spin images' length when its (first) describe node
/// describes spin, else MAX_DESCRIPTOR (also for a null graph, or parameters the describe node will
/// refuse). Every tabletop node sizes the frame block with it (frame_capacity()), so they agree.
[[nodiscard]] std::size_t descriptor_room(const engine::GraphSpec* graph) noexcept;

/// @brief Writes @p set as describe's spin_* parameters (what parse_describe_params reads back
/// equal). Start-up only.
void assign_spin_set(engine::ParamMap& params, const kernels::SpinSetParams& set);

/// @brief Grows @p graph's pool blocks, if they need it, to hold the frames they held with
/// MAX_DESCRIPTOR per object and the descriptor room its describe node needs (descriptor_room()).
void fit_pool_to_descriptors(engine::GraphSpec& graph);

/// @brief The specification of the graph's describe node (the default when it has none). Errors
/// name the node.
[[nodiscard]] Result<kernels::DescriptorSpec, std::string> descriptor_of_graph(
    const engine::GraphSpec& spec);

}  // namespace orthoflow::graphs
