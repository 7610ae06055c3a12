#include "graphs/tabletop.hpp"

#include "engine/ipc_nodes.hpp"
#include "graphs/nodes/body_filter_node.hpp"
#include "graphs/nodes/kinect_source.hpp"
#include "graphs/nodes/objects_output.hpp"
#include "graphs/nodes/recognise_node.hpp"
#include "graphs/nodes/replay_source.hpp"
#include "graphs/nodes/segment_nodes.hpp"
#include "graphs/nodes/session_log_node.hpp"
#include "graphs/nodes/source_nodes.hpp"
#include "graphs/nodes/track_describe_nodes.hpp"
#include "graphs/nodes/tum_source.hpp"

namespace orthoflow::graphs {

engine::NodeRegistry make_tabletop_registry(LearningService& learning, SessionLog& log,
                                            ObjectsHub* objects, LabelsWriter* labels,
                                            ArmStateFeed* arm_state) {
  engine::NodeRegistry registry;
  engine::add_generic_nodes(registry);
  engine::add_ipc_nodes(registry);  // ipc_subscribe / ipc_publish: graphs split across processes
  add_source_nodes(registry);
  add_kinect_source(registry);
  add_replay_source(registry);
  add_tum_source(registry);
  add_body_filter_node(registry, arm_state);
  add_segment_nodes(registry, labels);
  add_track_describe_nodes(registry);
  add_recognise_node(registry, learning);
  add_objects_output_node(registry, objects);
  add_session_log_node(registry, log);
  return registry;
}

}  // namespace orthoflow::graphs
