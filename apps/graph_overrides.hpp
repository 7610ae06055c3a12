#pragma once
/// @file
/// @brief The graph edits `orthoflow run` and `orthoflow bench latency` share: --source, --frames
/// and --rate applied to a graph spec before it is built.
#include <cstdint>
#include <string>

#include "core/result.hpp"
#include "engine/graph.hpp"

namespace orthoflow::apps {

/// @brief --source synthetic:SEED | pcd:DIR | kinect[:SERIAL] | kinect-sim[:SEED] | replay:DIR
/// (a fakenect recording, at its recorded pace) | tum:DIR (a TUM RGB-D benchmark folder, at its
/// recorded pace) and --frames
/// (synthetic sources; 0: the graph's) on
/// the graph's synthetic_source, pcd_source or kinect_source node. Errors say what is wrong.
[[nodiscard]] Result<void, std::string> apply_source(engine::GraphSpec& spec,
                                                     const std::string& source,
                                                     std::uint64_t frames);
/// @brief The --rate validator: "" when @p v is max or a number of Hz in [0.01, 1000] (the whole
/// text), otherwise the message.
[[nodiscard]] std::string check_rate(const std::string& v);
/// @brief --rate HZ | max (empty: the graph's period): the engine paces the source at this period,
/// which is also each frame's deadline; max: unpaced, no deadline. @pre validated by the option.
void apply_rate(engine::GraphSpec& spec, const std::string& rate);

}  // namespace orthoflow::apps
