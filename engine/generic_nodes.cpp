#include "engine/generic_nodes.hpp"

#include <chrono>
#include <cstring>

#include "engine/registry.hpp"

namespace orthoflow::engine {

namespace {

using Made = Result<std::unique_ptr<Node>, std::string>;
const std::vector<std::string> PORT_TYPES{"frame", "object"};

/// Source: one frame per call, optionally with a pool block whose first bytes carry the frame id.
class Ticker final : public Node {
 public:
  Ticker(std::int64_t frames, std::size_t payload_bytes, const NodeContext& context)
      : frames_(frames), payload_bytes_(payload_bytes), context_(context) {}
  std::span<const PortSpec> outputs() const noexcept override { return outputs_; }
  std::span<const PortSpec> inputs() const noexcept override { return {}; }
  bool stateful() const noexcept override { return true; }
  void process(const Message& /*in*/, Emitter& /*out*/) noexcept override {}
  SourceStatus produce(Message& out) noexcept override {
    if (frames_ > 0 && produced_ >= static_cast<std::uint64_t>(frames_)) return SourceStatus::END;
    out.value = static_cast<std::int64_t>(produced_);
    if (payload_bytes_ > 0 && context_.pool != nullptr) {
      auto block_result = context_.pool->acquire(context_.name, payload_bytes_);
      if (block_result) {
        out.payload = std::move(*block_result);
        stamp_payload(out.payload, produced_);
      } else {
        out.skipped = true;  // exhausted: the engine counts it as a drop at the source
      }
    }
    ++produced_;
    return SourceStatus::FRAME;
  }

 private:
  std::vector<PortSpec> outputs_{{"out", "frame", false}};
  std::int64_t frames_;
  std::size_t payload_bytes_;
  NodeContext context_;
  std::uint64_t produced_ = 0;
};

/// Pass-through that optionally burns CPU (spin_us) and adds a constant to the value; stateless
/// unless serial=1 (then the engine runs it one message at a time, e.g. to model a slow tracker).
class Busy final : public Node {
 public:
  Busy(const std::string& type, std::int64_t spin_us, std::int64_t add, bool serial)
      : ports_{{"in", type, true}, {"out", type, false}},
        spin_us_(spin_us),
        add_(add),
        serial_(serial) {}
  std::span<const PortSpec> inputs() const noexcept override { return {ports_.data(), 1}; }
  std::span<const PortSpec> outputs() const noexcept override { return {ports_.data() + 1, 1}; }
  bool stateful() const noexcept override { return serial_; }
  void process(const Message& in, Emitter& out) noexcept override {
    if (spin_us_ > 0) {
      const auto until = std::chrono::steady_clock::now() + std::chrono::microseconds(spin_us_);
      while (std::chrono::steady_clock::now() < until) {}
    }
    Message result = in;
    result.value += add_;
    out.emit(0, result);
  }

 private:
  std::vector<PortSpec> ports_;
  std::int64_t spin_us_;
  std::int64_t add_;
  bool serial_;
};

/// Splits a frame into `objects` object messages (value = frame value + object index); with
/// vary=1 the count cycles through 0..objects with the frame id. Zero objects still send one
/// message (object_count = 0) so that the join downstream completes the frame.
class Fanout final : public Node {
 public:
  Fanout(std::uint32_t objects, bool vary) : objects_(objects), vary_(vary) {}
  std::span<const PortSpec> inputs() const noexcept override { return {ports_.data(), 1}; }
  std::span<const PortSpec> outputs() const noexcept override { return {ports_.data() + 1, 1}; }
  bool stateful() const noexcept override { return false; }
  void process(const Message& in, Emitter& out) noexcept override {
    const auto count = vary_ ? static_cast<std::uint32_t>(in.frame_id % (objects_ + 1u)) : objects_;
    Message object = in;
    object.object_count = count;
    for (std::uint32_t i = 0; i < (count == 0 ? 1u : count); ++i) {
      object.object_index = i;
      object.value = in.value + (count == 0 ? 0 : static_cast<std::int64_t>(i));
      out.emit(0, object);
    }
  }

 private:
  std::vector<PortSpec> ports_{{"in", "frame", true}, {"out", "object", false}};
  std::uint32_t objects_;
  bool vary_;
};

/// Collects the object messages of each frame and emits one frame message with their value sum.
/// Per-frame state lives in the engine's frame slot (Message::slot), so the table never grows.
class Join final : public Node {
 public:
  explicit Join(std::size_t slots) : slots_(slots) {}
  std::span<const PortSpec> inputs() const noexcept override { return {ports_.data(), 1}; }
  std::span<const PortSpec> outputs() const noexcept override { return {ports_.data() + 1, 1}; }
  bool stateful() const noexcept override { return true; }
  bool wants_skipped() const noexcept override { return true; }
  void process(const Message& in, Emitter& out) noexcept override {
    Slot& slot = slots_[in.slot];
    if (slot.arrived == 0) slot = Slot{in.frame_id, 0, 0, false};
    OF_ENFORCE(slot.frame_id == in.frame_id, "join: more frames in flight than slots");
    ++slot.arrived;
    slot.skipped = slot.skipped || in.skipped;
    if (!in.skipped && in.object_count > 0) slot.sum += in.value;  // an empty frame adds nothing
    if (slot.arrived < (in.object_count == 0 ? 1u : in.object_count)) return;
    Message frame = in;
    frame.object_index = 0;
    frame.object_count = 1;
    frame.skipped = slot.skipped;
    frame.value = slot.sum;
    slot.arrived = 0;
    out.emit(0, frame);
  }

 private:
  struct Slot {
    std::uint64_t frame_id = 0;
    std::uint32_t arrived = 0;
    std::int64_t sum = 0;
    bool skipped = false;
  };
  std::vector<PortSpec> ports_{{"in", "object", true}, {"out", "frame", false}};
  std::vector<Slot> slots_;
};

Made make_ticker(const ParamMap& params, const NodeContext& context) {
  if (auto ok = params.only({"frames", "payload_bytes"}); !ok) return err(ok.error());
  auto frames_result = params.integer("frames", 0, 0, std::int64_t{1} << 40);
  if (!frames_result) return err(frames_result.error());
  const std::int64_t limit =
      context.pool ? static_cast<std::int64_t>(context.pool->block_bytes()) : 0;
  auto bytes_result = params.integer("payload_bytes", 0, 0, limit);
  if (!bytes_result) return err(bytes_result.error() + " (the pool's block_bytes)");
  return std::unique_ptr<Node>(
      new Ticker(*frames_result, static_cast<std::size_t>(*bytes_result), context));
}

Made make_busy(const ParamMap& params) {
  if (auto ok = params.only({"type", "spin_us", "add", "serial"}); !ok) return err(ok.error());
  auto serial_result = params.integer("serial", 0, 0, 1);
  if (!serial_result) return err(serial_result.error());
  auto type_result = params.choice("type", "frame", PORT_TYPES);
  auto spin_result = params.integer("spin_us", 0, 0, 10'000'000);
  auto add_result = params.integer("add", 0, -1'000'000, 1'000'000);
  if (!type_result) return err(type_result.error());
  if (!spin_result) return err(spin_result.error());
  if (!add_result) return err(add_result.error());
  return std::unique_ptr<Node>(
      new Busy(*type_result, *spin_result, *add_result, *serial_result == 1));
}

Made make_fanout(const ParamMap& params) {
  if (auto ok = params.only({"objects", "vary"}); !ok) return err(ok.error());
  auto objects_result = params.integer("objects", 1, 0, 1024);
  auto vary_result = params.integer("vary", 0, 0, 1);
  if (!objects_result) return err(objects_result.error());
  if (!vary_result) return err(vary_result.error());
  return std::unique_ptr<Node>(
      new Fanout(static_cast<std::uint32_t>(*objects_result), *vary_result == 1));
}

}  // namespace

void CountSink::process(const Message& in, Emitter& /*out*/) noexcept {
  received.fetch_add(1, std::memory_order_relaxed);
  if (!first_ && in.frame_id < last_frame.load(std::memory_order_relaxed))
    out_of_order.fetch_add(1);
  first_ = false;
  last_frame.store(in.frame_id, std::memory_order_relaxed);
  if (in.skipped) {
    skipped.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  if (!payload_matches(in.payload, in.frame_id)) payload_errors.fetch_add(1);
  value_sum.fetch_add(in.value, std::memory_order_relaxed);
}

void stamp_payload(const memory_pool::BlockHandle& payload, std::uint64_t frame_id) noexcept {
  const auto bytes = payload.bytes();
  if (bytes.size() >= sizeof(frame_id)) std::memcpy(bytes.data(), &frame_id, sizeof(frame_id));
}

bool payload_matches(const memory_pool::BlockHandle& payload, std::uint64_t frame_id) noexcept {
  const auto bytes = payload.bytes();
  if (bytes.size() < sizeof(frame_id)) return true;
  std::uint64_t stored = 0;
  std::memcpy(&stored, bytes.data(), sizeof(stored));
  return stored == frame_id;
}

Result<std::unique_ptr<Node>, std::string> make_generic_node(const std::string& kind,
                                                             const ParamMap& params,
                                                             const NodeContext& context) {
  if (kind == "ticker") return make_ticker(params, context);
  if (kind == "busy" || kind == "pass") return make_busy(params);
  if (kind == "fanout") return make_fanout(params);
  if (kind == "join") {
    if (auto ok = params.only({}); !ok) return err(ok.error());
    return std::unique_ptr<Node>(new Join(context.max_in_flight));
  }
  if (kind == "count") {
    if (auto ok = params.only({"type"}); !ok) return err(ok.error());
    auto type_result = params.choice("type", "frame", PORT_TYPES);
    if (!type_result) return err(type_result.error());
    return std::unique_ptr<Node>(new CountSink(*type_result));
  }
  return err("unknown generic node kind '" + kind + "'");
}

void add_generic_nodes(NodeRegistry& registry) {
  const char* const descriptions[][2] = {
      {"ticker", "source: frames=N (0 = endless), payload_bytes=B (pool block per frame)"},
      {"pass", "stateless pass-through: type=frame|object"},
      {"busy", "pass-through with work: type, spin_us, add (added to value), serial=0|1"},
      {"fanout", "splits a frame into objects=N object messages (vary=1: 0..N by frame id)"},
      {"join", "stateful: joins the object messages of each frame, value = sum"},
      {"count", "stateful sink: counts frames, checks order and payload; type=frame|object"}};
  for (const auto& [kind, description] : descriptions) {
    const std::string name = kind;
    registry.add(name, description, [name](const ParamMap& params, const NodeContext& context) {
      return make_generic_node(name, params, context);
    });
  }
}

}  // namespace orthoflow::engine
