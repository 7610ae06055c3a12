#pragma once
/// @file
/// @brief The segmentation a `--graph FILE|tabletop` argument names (the preprocess, table and
/// objects nodes of that graph; "tabletop" is the embedded graph `orthoflow run` runs), shared by
/// `segment` and `evaluate-segmentation` so both mean the product's chain.
#include <string>

#include "core/result.hpp"
#include "engine/graph.hpp"
#include "graphs/embedded_graphs.hpp"
#include "graphs/nodes/segment_params.hpp"

namespace orthoflow::apps {

[[nodiscard]] inline Result<graphs::TabletopSegmentation, std::string> segmentation_of_graph_arg(
    const std::string& graph) {
  auto spec =
      graph == "tabletop"
          ? engine::parse_graph(std::string(graphs::embedded_tabletop_yaml()), "tabletop.yaml")
          : engine::load_graph_file(graph);
  if (!spec) return err(engine::to_string(spec.error()));
  return graphs::segmentation_of_graph(*spec);
}

}  // namespace orthoflow::apps
