#pragma once
/// @file
/// @brief The `recognise` kind (stateful, ordered frames): asks the learner for every described
/// object, smooths the answers over each track (majority of the last `smoothing` answers), keeps
/// each track's key views (graphs/nodes/track_memory.hpp), and applies the learning channel's
/// commands (graphs/channels/learning_channel.hpp: teach a track or the object at a position,
/// correct, forget, ask; each acknowledged) and, with `instructor: 1`, the scripted instructor of
/// the synthetic session, which teaches the first instance of every category it knows the truth of
/// (session_script.hpp says which) in 3 lessons, as the thesis's simulated teacher introduces a
/// category (Algorithm 7.1).
#include "engine/registry.hpp"
#include "graphs/services/learning_service.hpp"

namespace orthoflow::graphs {

/// @brief Registers recognise, bound to @p service (which must outlive every graph built).
void add_recognise_node(engine::NodeRegistry& registry, LearningService& service);

}  // namespace orthoflow::graphs
