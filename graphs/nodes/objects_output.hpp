#pragma once
/// @file
/// @brief Results out. The `objects_output` kind (ordered, after recognise) turns every frame's
/// objects into one engine::ObjectListPayload (track id, label or Unknown, score, object frame,
/// boxes, point count, frame stamps and the frame's age at decision) and hands it
///   - to in-process consumers: every ObjectsSubscription of the ObjectsHub the registry was made
///   with;
///   - on its `objects` port (type objects), whose messages an `ipc_publish` node sends to the
///   iceoryx
///     topic `orthoflow/<graph>/objects` (graphs/perception.yaml; `orthoflow run
///     --publish-objects`).
/// Real time: publish() copies the used part of the list into each subscriber's ring (never waits:
/// a full ring drops the newest list and counts it); nothing allocates after start-up.
#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include "core/spsc_ring.hpp"
#include "engine/object_list_payload.hpp"
#include "engine/registry.hpp"
#include "graphs/frame/frame_block.hpp"
#include "graphs/nodes/camera_tap.hpp"

namespace orthoflow::graphs {

class ObjectsHub;

/// @brief One consumer's queue of object lists. Thread-compatible: one thread polls it.
/// @pre destroyed before its hub.
class ObjectsSubscription {
 public:
  ~ObjectsSubscription();
  ObjectsSubscription(const ObjectsSubscription&) = delete;
  ObjectsSubscription& operator=(const ObjectsSubscription&) = delete;
  /// @brief Takes the oldest queued list (count entries valid). Lock-free.
  bool poll(engine::ObjectListPayload& out) noexcept;
  /// @brief Lists dropped because this consumer was behind.
  [[nodiscard]] std::uint64_t dropped() const noexcept { return dropped_.load(); }

 private:
  friend class ObjectsHub;
  ObjectsSubscription(ObjectsHub& hub, std::size_t depth) : hub_(hub), lists_(depth) {}
  ObjectsHub& hub_;
  core::SpscRing<engine::ObjectListPayload> lists_;
  std::atomic<std::uint64_t> dropped_{0};
};

/// @brief Fans object lists out to in-process consumers. @note subscribe() and the subscriptions'
/// destructors are thread-safe; publish() is for the objects_output node (one thread at a time).
class ObjectsHub {
 public:
  /// @brief A new consumer queue of @p depth lists (allocated now). Thread-safe.
  [[nodiscard]] std::unique_ptr<ObjectsSubscription> subscribe(std::size_t depth = 8);
  /// @brief Copies @p list (its header and count entries) to every consumer. Allocation-free.
  void publish(const engine::ObjectListPayload& list) noexcept;
  [[nodiscard]] std::uint64_t published() const noexcept { return published_.load(); }
  /// @brief The camera view of the frames whose lists are published (offered by objects_output
  /// after each publish(); copies only while a viewer asks for it).
  [[nodiscard]] CameraTap& camera() noexcept { return camera_; }

 private:
  friend class ObjectsSubscription;
  void unsubscribe(ObjectsSubscription* s) noexcept;
  std::mutex subscribers_lock_;  // taken by publish() only with try_lock: a (un)subscribe in
                                 // progress makes that frame's list skip the consumers, never wait
  std::vector<ObjectsSubscription*> subscribers_;
  std::atomic<std::uint64_t> published_{0}, skipped_{0};
  CameraTap camera_;
};

/// @brief Fills @p out from the objects of @p block (frame @p frame_id, decided at @p decided_ns).
void fill_object_list(const FrameBlock& block, std::uint64_t frame_id, std::int64_t decided_ns,
                      engine::ObjectListPayload& out) noexcept;

/// @brief Registers objects_output, bound to @p hub (may be null: no in-process consumers).
void add_objects_output_node(engine::NodeRegistry& registry, ObjectsHub* hub);

}  // namespace orthoflow::graphs
