#include "graphs/node_support.hpp"

namespace orthoflow::graphs {

Result<std::size_t, std::string> frame_capacity(const engine::NodeContext& context) {
  const std::size_t bytes = context.pool == nullptr ? 0 : context.pool->block_bytes();
  const std::size_t capacity = FrameBlock::capacity_for(bytes);
  if (capacity < 1024) {
    return err(
        std::string(context.name) + ": pool blocks of " + std::to_string(bytes) +
        " bytes are too small for tabletop frames (a 640x480 frame needs pool block_bytes >= " +
        std::to_string(FrameBlock::bytes_for(640 * 480)) + ")");
  }
  return capacity;
}

}  // namespace orthoflow::graphs
