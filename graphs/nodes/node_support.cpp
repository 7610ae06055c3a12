#include "graphs/nodes/node_support.hpp"

#include "graphs/nodes/descriptor_params.hpp"

namespace orthoflow::graphs {

Result<std::size_t, std::string> frame_capacity(const engine::NodeContext& context) {
  const std::size_t bytes = context.pool == nullptr ? 0 : context.pool->block_bytes();
  const std::size_t room = descriptor_room(context.graph);
  const std::size_t capacity = FrameBlock::capacity_for(bytes, room);
  if (capacity < 1024) {
    return err(std::string(context.name) + ": pool blocks of " + std::to_string(bytes) +
               " bytes are too small for tabletop frames (a 640x480 frame with " +
               std::to_string(room) + " descriptor floats per object needs pool block_bytes >= " +
               std::to_string(FrameBlock::bytes_for(640 * 480, room)) + ")");
  }
  return capacity;
}

std::string full_frame_too_large(std::string_view kind, std::size_t capacity,
                                 const engine::NodeContext& context) {
  return std::string(kind) + ": pool blocks hold " + std::to_string(capacity) +
         " points, a 640x480 frame needs 307200 (raise pool block_bytes to " +
         std::to_string(FrameBlock::bytes_for(640 * 480, descriptor_room(context.graph))) + ")";
}

}  // namespace orthoflow::graphs
