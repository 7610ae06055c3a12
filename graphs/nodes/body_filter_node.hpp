#pragma once
/// @file
/// @brief The robot-body filter (thesis: C_robot; issue 21, item 4), node kind `body_filter`,
/// between the source and preprocess: every point of the frame inside the arm's link model (the
/// JACO's capsules at the streamed joint angles, manipulation/arm_body.hpp, placed in the camera
/// frame by the robot frames file) becomes NaN, so segmentation never sees the arm or the gripper
/// and nothing teaches them as objects. Also C_instructor: `exclude` names zones (capsules in the
/// camera frame, e.g. the table's edge on the person's side) whose points are removed the same way,
/// so a hand reaching in is never segmented or taught; `arm: none` applies the zones alone.
///
/// Policy: a frame is filtered only with a fresh, sane arm state. No state yet, a state older
/// (or newer) than max_state_age_ms against the frame's time, an arm reporting a link fault or
/// non-finite joints: the frame is dropped (a tombstone goes on, so downstream sees one message per
/// frame and publishes no objects for it) and the reason is counted (telemetry group "body").
/// Dropping is the safe side: an unfiltered frame would show the arm as an object.
///
/// The filter writes into the frame's own block: a frame held in an iceoryx chunk (ipc_subscribe)
/// is first copied into the block (the chunk is shared with other subscribers). So body_filter
/// must be its source's only consumer. No allocation after start-up.
#include <string>

#include "core/result.hpp"
#include "engine/graph.hpp"
#include "engine/registry.hpp"
#include "graphs/services/arm_state_feed.hpp"

namespace orthoflow::graphs {

/// @brief Registers `body_filter`. Its `state: channel` reads @p channel (null: that choice is
/// refused); `state: ipc` (the default) subscribes to `state_topic` when the graph is built to run.
void add_body_filter_node(engine::NodeRegistry& registry, ArmStateFeed* channel);

/// @brief Puts a `body_filter` node named "body" with @p params on the edge into the graph's
/// preprocess node (what `orthoflow run --robot-frames` does). @return why not: no preprocess, not
/// exactly one edge into it, or a node named "body" already there.
[[nodiscard]] Result<void, std::string> insert_body_filter(engine::GraphSpec& spec,
                                                           const engine::ParamMap& params);

}  // namespace orthoflow::graphs
