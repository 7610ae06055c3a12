#pragma once
/// @file
/// @brief Domain-free node kinds used by examples, tests and benchmarks. They know nothing about
/// point clouds: they move frame ids, small integer values and pool blocks around.
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/result.hpp"
#include "engine/node.hpp"
#include "engine/params.hpp"

namespace orthoflow::engine {

/// @brief Sink kind "count": counts frames and checks order and payload stamps.
/// Readable from other threads after the graph stopped (counters are atomics).
class CountSink final : public Node {
 public:
  explicit CountSink(std::string type) : inputs_{{"in", std::move(type), true}} {}
  std::span<const PortSpec> inputs() const noexcept override { return inputs_; }
  std::span<const PortSpec> outputs() const noexcept override { return {}; }
  bool stateful() const noexcept override { return true; }
  bool wants_skipped() const noexcept override { return true; }
  void process(const Message& in, Emitter& out) noexcept override;

  std::atomic<std::uint64_t> received{0};        ///< messages, tombstones included
  std::atomic<std::uint64_t> skipped{0};         ///< tombstones
  std::atomic<std::uint64_t> out_of_order{0};    ///< frame id lower than the previous one
  std::atomic<std::uint64_t> payload_errors{0};  ///< payload does not start with its frame id
  std::atomic<std::int64_t> value_sum{0};        ///< sum of values of non-skipped messages
  std::atomic<std::uint64_t> last_frame{0};

 private:
  std::vector<PortSpec> inputs_;
  bool first_ = true;
};

/// @brief Writes `frame_id` into the first 8 bytes of a payload block (the ticker does this).
void stamp_payload(const memory_pool::BlockHandle& payload, std::uint64_t frame_id) noexcept;
/// @brief True if a payload's first 8 bytes equal `frame_id` (or the payload is empty).
[[nodiscard]] bool payload_matches(const memory_pool::BlockHandle& payload,
                                   std::uint64_t frame_id) noexcept;

/// @brief Builds the generic kinds by name: ticker, pass, busy, fanout, join, count.
/// @return nullptr-free node or an error message naming the bad parameter.
[[nodiscard]] Result<std::unique_ptr<Node>, std::string> make_generic_node(
    const std::string& kind, const ParamMap& params, const NodeContext& context);

}  // namespace orthoflow::engine
