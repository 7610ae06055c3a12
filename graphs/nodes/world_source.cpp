#include "graphs/nodes/world_source.hpp"

#include <memory>

#include "graphs/nodes/frame_source.hpp"
#include "graphs/nodes/node_support.hpp"

namespace orthoflow::graphs {

namespace {

class WorldSource final : public FrameSource {
 public:
  WorldSource(std::size_t capacity, const engine::NodeContext& context, WorldFeed& feed)
      : FrameSource(capacity, context), feed_(feed) {
    cloud_.reserve(640 * 480);
  }
  engine::SourceStatus produce(engine::Message& out) noexcept override {
    const simulation::Scene* scene = feed_.next_frame(cloud_);
    if (scene == nullptr) return engine::SourceStatus::END;
    if (!take_block(out)) return engine::SourceStatus::FRAME;
    take_up(cloud_, scene->table);
    emit_cloud(out, cloud_);
    write_truth(out, scene->objects);
    return engine::SourceStatus::FRAME;
  }

 private:
  WorldFeed& feed_;
  kernels::PointCloud cloud_;
};

}  // namespace

void add_world_source_node(engine::NodeRegistry& registry, WorldFeed* feed) {
  registry.add(
      "world_source",
      "frames of the closed-loop simulated world of this process (orthoflow demo); no "
      "parameters",
      [feed](const engine::ParamMap& params, const engine::NodeContext& context) -> NodeResult {
        if (feed == nullptr)
          return err(
              std::string("world_source: no closed-loop world in this process (orthoflow demo has "
                          "one)"));
        if (auto ok = params.only({}); !ok) return err(ok.error());
        auto capacity = frame_capacity(context);
        if (!capacity) return err(capacity.error());
        return std::unique_ptr<engine::Node>(new WorldSource(*capacity, context, *feed));
      });
}

}  // namespace orthoflow::graphs
