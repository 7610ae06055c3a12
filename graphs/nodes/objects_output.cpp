#include "graphs/nodes/objects_output.hpp"

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <cstring>

#include "graphs/nodes/node_support.hpp"

namespace orthoflow::graphs {

namespace {

using Clock = std::chrono::steady_clock;
const engine::PortSpec PORTS[] = {FRAME_IN, FRAME_OUT, {"objects", "objects", false}};

/// Copies the header and the first count entries (the rest of the 12.9 KB list is not read).
void copy_list(const engine::ObjectListPayload& from, engine::ObjectListPayload& to) noexcept {
  std::memcpy(static_cast<void*>(&to), &from, offsetof(engine::ObjectListPayload, objects));
  std::memcpy(static_cast<void*>(to.objects), from.objects,
              from.count * sizeof(engine::ObjectEntry));
}

class ObjectsOutput final : public engine::Node {
 public:
  ObjectsOutput(std::size_t capacity, ObjectsHub* hub, std::unique_ptr<memory_pool::BlockPool> pool)
      : capacity_(capacity), hub_(hub), pool_(std::move(pool)) {}
  std::span<const engine::PortSpec> inputs() const noexcept override { return {PORTS, 1}; }
  std::span<const engine::PortSpec> outputs() const noexcept override { return {PORTS + 1, 2}; }
  bool stateful() const noexcept override { return true; }

  void process(const engine::Message& in, engine::Emitter& out) noexcept override {
    out.emit(0, in);
    if (in.skipped) return;
    auto block = pool_->acquire("objects_output", sizeof(engine::ObjectListPayload));
    if (!block)
      return;  // every list still in flight downstream: this frame's is not sent on the port
    auto* list =
        new (block->bytes().data()) engine::ObjectListPayload();  // header and count set below
    const FrameBlock frame_block = block_of(in, capacity_);
    const std::int64_t now_ns = Clock::now().time_since_epoch().count();
    fill_object_list(frame_block, in.frame_id, now_ns, *list);
    if (hub_ != nullptr) {
      hub_->publish(*list);
      if (auto frame = frame_block.frame()) hub_->camera().offer(*frame, now_ns);
    }
    engine::Message objects = in;
    objects.payload = std::move(*block);
    out.emit(1, objects);
  }

 private:
  std::size_t capacity_;
  ObjectsHub* hub_;
  std::unique_ptr<memory_pool::BlockPool> pool_;
};

}  // namespace

void fill_object_list(const FrameBlock& block, std::uint64_t frame_id, std::int64_t decided_ns,
                      engine::ObjectListPayload& out) noexcept {
  out.reset_header();
  out.frame_id = frame_id;
  out.decided_ns = decided_ns;
  const FrameState& s = block.state();
  if (auto frame = block.frame()) {
    out.sensor_stamp_ns = frame->header->sensor_stamp_ns;
    out.host_stamp_ns = frame->header->host_stamp_ns;
    out.age_ns = out.host_stamp_ns != 0 ? decided_ns - out.host_stamp_ns : 0;
  }
  out.table_reason = static_cast<std::uint8_t>(static_cast<unsigned>(s.table_reason) + 1U);
  out.gravity = static_cast<std::uint8_t>(static_cast<unsigned>(s.gravity) + 1U);
  out.count = std::min<std::uint32_t>(s.object_count, engine::OBJECT_LIST_CAPACITY);
  for (std::uint32_t k = 0; k < out.count; ++k) {
    const ObjectRecord& o = s.objects[k];
    engine::ObjectEntry& e = out.objects[k];
    e.track_id = o.track_id;
    e.label = o.unknown ? Text{} : o.label;
    e.score = o.score;
    e.unknown = o.unknown || !(o.recognised || o.carried) ? 1U : 0U;
    std::copy(o.stats.centroid.begin(), o.stats.centroid.end(), e.centroid);
    std::copy(o.frame.begin(), o.frame.end(), e.frame);
    std::copy(o.bbox.begin(), o.bbox.end(), e.bbox);
    std::copy(o.stats.bbox_min.begin(), o.stats.bbox_min.end(), e.bbox_min);
    std::copy(o.stats.bbox_max.begin(), o.stats.bbox_max.end(), e.bbox_max);
    e.point_count = o.count;
    e.flags =
        (o.described ? engine::OBJECT_DESCRIBED : 0U) | (o.moving ? engine::OBJECT_MOVING : 0U) |
        (o.key_view ? engine::OBJECT_KEY_VIEW : 0U) | (o.fragment ? engine::OBJECT_FRAGMENT : 0U) |
        (o.taught ? engine::OBJECT_TAUGHT : 0U) | (o.carried ? engine::OBJECT_CARRIED : 0U);
  }
}

ObjectsSubscription::~ObjectsSubscription() { hub_.unsubscribe(this); }

bool ObjectsSubscription::poll(engine::ObjectListPayload& out) noexcept {
  const engine::ObjectListPayload* front = lists_.peek();
  if (front == nullptr) return false;
  copy_list(*front, out);
  lists_.release(1);
  return true;
}

std::unique_ptr<ObjectsSubscription> ObjectsHub::subscribe(std::size_t depth) {
  std::unique_ptr<ObjectsSubscription> s(new ObjectsSubscription(*this, depth == 0 ? 1 : depth));
  const std::lock_guard lock(subscribers_lock_);
  subscribers_.push_back(s.get());
  return s;
}

void ObjectsHub::unsubscribe(ObjectsSubscription* s) noexcept {
  const std::lock_guard lock(subscribers_lock_);
  std::erase(subscribers_, s);
}

void ObjectsHub::publish(const engine::ObjectListPayload& list) noexcept {
  published_.fetch_add(1);
  std::unique_lock lock(subscribers_lock_, std::try_to_lock);
  if (!lock.owns_lock()) {
    skipped_.fetch_add(1);
    return;
  }
  for (ObjectsSubscription* s : subscribers_) {
    engine::ObjectListPayload* slot = s->lists_.claim();
    if (slot == nullptr) {
      s->dropped_.fetch_add(1);
      continue;
    }
    copy_list(list, *slot);
    s->lists_.publish();
  }
}

void add_objects_output_node(engine::NodeRegistry& registry, ObjectsHub* hub) {
  registry.add(
      "objects_output",
      "results out: each frame's objects as one ObjectListPayload to in-process consumers and on "
      "port "
      "'objects' (connect an ipc_publish of type objects for orthoflow/<graph>/objects)",
      [hub](const engine::ParamMap& params, const engine::NodeContext& context) -> NodeResult {
        auto capacity = frame_capacity(context);
        if (!capacity) return err(capacity.error());
        if (auto ok = params.only({}); !ok) return err(ok.error());
        // Lists in flight downstream (an ipc_publish) at most: one per frame in flight, and spare.
        const memory_pool::PoolConfig config{sizeof(engine::ObjectListPayload),
                                             context.max_in_flight + 4, "objects_output"};
        auto pool = memory_pool::BlockPool::create_owned(config);
        if (!pool) return err(memory_pool::to_string(pool.error()));
        return std::unique_ptr<engine::Node>(new ObjectsOutput(*capacity, hub, std::move(*pool)));
      });
}

}  // namespace orthoflow::graphs
