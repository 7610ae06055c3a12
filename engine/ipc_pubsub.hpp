#pragma once
/// @file
/// @brief Untyped iceoryx publisher and subscriber for orthoflow payloads: topic names
/// `orthoflow/<graph-or-device>/<stream>`, payload header checks, a pool check before every loan,
/// per-topic queue policies and drop counters. iceoryx types stay inside ipc_pubsub.cpp.
///
/// Every payload starts with `uint32 type_id, uint16 version` and holds `uint64 payload_bytes`
/// (header included) at byte offset 48, like FrameHeader.
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>

#include "engine/ipc_runtime.hpp"

namespace orthoflow::engine {

/// @brief An iceoryx service description: `service/instance/event`.
struct IpcTopic {
  std::string service, instance, event;
  [[nodiscard]] std::string str() const { return service + "/" + instance + "/" + event; }
};

/// @brief Parses `service/instance/event` (each 1..100 of [A-Za-z0-9_.-]). @return BAD_TOPIC.
[[nodiscard]] Result<IpcTopic, IpcError> parse_topic(const std::string& text);

/// @brief What a topic carries: checked on both ends.
struct IpcPayloadType {
  std::uint32_t type_id = 0;
  std::uint16_t version = 0;
};

/// @brief Byte offset of `uint64 payload_bytes` in every payload header.
inline constexpr std::size_t PAYLOAD_BYTES_OFFSET = 48;
/// @brief Smallest payload: the header up to and including payload_bytes.
inline constexpr std::size_t PAYLOAD_HEADER_BYTES = 56;
/// @brief Alignment of every loan (FrameHeader and ObjectListPayload are 64-byte aligned).
inline constexpr std::uint32_t PAYLOAD_ALIGNMENT = 64;

/// @brief Validates the common header of `bytes` against `type`; returns its payload_bytes.
/// @return WRONG_TYPE / WRONG_VERSION / BAD_SIZE (payload_bytes below 56 or above bytes.size()),
/// naming `topic`. Thread-safe, reads only bytes[0, 56).
[[nodiscard]] Result<std::uint64_t, IpcError> check_payload_header(std::span<const std::byte> bytes,
                                                                   IpcPayloadType type,
                                                                   const std::string& topic);

/// @brief Subscriber queue policy. LATEST: keep only the newest chunk (older ones are dropped and
/// counted). QUEUE: a FIFO of `depth`, the oldest dropped and counted when full. LOSSLESS: a FIFO
/// of `depth` whose publisher waits when it is full (only if the publisher is LOSSLESS too).
enum class IpcPolicy { LATEST, QUEUE, LOSSLESS };

/// @brief Publisher settings. @pre max_payload_bytes >= 56.
struct IpcPublisherConfig {
  IpcPayloadType type;
  std::uint64_t max_payload_bytes = 4096;  ///< checked against RouDi's pools at creation
  std::uint64_t history = 0;               ///< samples kept for late subscribers
  bool lossless = false;                   ///< wait for LOSSLESS subscribers instead of dropping
};

/// @brief Subscriber settings.
struct IpcSubscriberConfig {
  IpcPayloadType type;
  IpcPolicy policy = IpcPolicy::LATEST;
  std::uint64_t depth = 1;    ///< queue capacity (LATEST uses 1), 1..256
  std::uint64_t history = 0;  ///< samples requested from the publisher's history on connect
};

/// @brief Counters, readable from any thread (relaxed atomics).
struct IpcCounters {
  std::atomic<std::uint64_t> samples{0};        ///< published / taken
  std::atomic<std::uint64_t> dropped{0};        ///< subscriber: gaps in the publisher's sequence
  std::atomic<std::uint64_t> rejected{0};       ///< header mismatch (never handed out)
  std::atomic<std::uint64_t> loan_failures{0};  ///< publisher: exhausted or too many loans
  std::atomic<std::uint64_t> unpublished{0};    ///< publisher: not sent, RouDi was lost
};

/// @brief Publishes payloads on one topic. Move-only; destroy before the process exits.
/// @note Not thread-safe: one thread loans and publishes (a serial node).
class IpcPublisher {
 public:
  /// @brief Offers `topic`. Checks that `pools` holds a max_payload_bytes chunk (NO_FITTING_POOL).
  /// @pre init_ipc_runtime succeeded (else ROUDI_UNREACHABLE). Start-up only.
  [[nodiscard]] static Result<std::unique_ptr<IpcPublisher>, IpcError> create(
      const IpcTopic& topic, const IpcPublisherConfig& config, const IpcPools& pools);
  ~IpcPublisher();
  IpcPublisher(const IpcPublisher&) = delete;
  IpcPublisher& operator=(const IpcPublisher&) = delete;

  /// @brief Loans a chunk of `bytes` (uninitialised, 64-byte aligned) to fill in place: the
  /// zero-copy path. @return BAD_SIZE above max_payload_bytes, POOL_EXHAUSTED, TOO_MANY_LOANS.
  /// No heap allocation; never aborts.
  [[nodiscard]] Result<std::span<std::byte>, IpcError> loan(std::size_t bytes) noexcept;
  /// @brief Publishes a loaned chunk after checking its header (type, version, payload_bytes <=
  /// loaned bytes). On error the chunk is released.
  [[nodiscard]] Result<void, IpcError> publish(std::span<std::byte> loaned) noexcept;
  /// @brief Returns a loaned chunk unpublished.
  void release(std::span<std::byte> loaned) noexcept;
  /// @brief Loans payload_bytes of `payload` (its header says how many), copies once, publishes.
  [[nodiscard]] Result<void, IpcError> publish_copy(std::span<const std::byte> payload) noexcept;
  /// @brief True if a subscriber is connected.
  [[nodiscard]] bool has_subscribers() const noexcept;
  /// @brief Counts a sample the caller did not publish because RouDi was lost (`unpublished`).
  void count_unpublished() noexcept {
    counters_.unpublished.fetch_add(1, std::memory_order_relaxed);
  }
  [[nodiscard]] const IpcCounters& counters() const noexcept { return counters_; }
  [[nodiscard]] const std::string& topic() const noexcept { return topic_; }

 private:
  struct Impl;
  IpcPublisher(std::unique_ptr<Impl> impl, std::string topic, const IpcPublisherConfig& config);
  std::unique_ptr<Impl> impl_;
  std::string topic_;
  IpcPublisherConfig config_;
  IpcCounters counters_;
};

class IpcSubscriber;

/// @brief One received chunk, held until destroyed (then released to iceoryx). Move-only.
/// @pre Destroyed before its subscriber.
class IpcSample {
 public:
  IpcSample() noexcept = default;
  IpcSample(IpcSample&& other) noexcept;
  IpcSample& operator=(IpcSample&& other) noexcept;
  ~IpcSample();
  IpcSample(const IpcSample&) = delete;
  IpcSample& operator=(const IpcSample&) = delete;
  /// @brief The payload [0, payload_bytes) as written by the publisher.
  [[nodiscard]] std::span<const std::byte> bytes() const noexcept { return bytes_; }
  /// @brief The publisher's sequence number (consecutive per publisher).
  [[nodiscard]] std::uint64_t sequence() const noexcept { return sequence_; }
  [[nodiscard]] explicit operator bool() const noexcept { return owner_ != nullptr; }
  /// @brief Releases the chunk now.
  void reset() noexcept;

 private:
  friend class IpcSubscriber;
  IpcSubscriber* owner_ = nullptr;
  std::span<const std::byte> bytes_;
  std::uint64_t sequence_ = 0;
};

/// @brief Subscribes to one topic. Not thread-safe: one thread takes (a source node).
class IpcSubscriber {
 public:
  /// @pre init_ipc_runtime succeeded (else ROUDI_UNREACHABLE). depth in 1..256 (else BAD_TOPIC).
  [[nodiscard]] static Result<std::unique_ptr<IpcSubscriber>, IpcError> create(
      const IpcTopic& topic, const IpcSubscriberConfig& config);
  ~IpcSubscriber();
  IpcSubscriber(const IpcSubscriber&) = delete;
  IpcSubscriber& operator=(const IpcSubscriber&) = delete;

  /// @brief Takes the next chunk (LATEST: the newest, releasing older queued ones as drops).
  /// @return nullopt if none is queued; WRONG_TYPE / WRONG_VERSION / BAD_SIZE for a chunk that
  /// fails the header check (released, counted in rejected); TOO_MANY_LOANS when 256 are held.
  /// No heap allocation on success or empty.
  [[nodiscard]] Result<std::optional<IpcSample>, IpcError> take() noexcept;
  /// @brief True if a publisher is connected to this subscriber.
  [[nodiscard]] bool subscribed() const noexcept;
  [[nodiscard]] const IpcCounters& counters() const noexcept { return counters_; }
  [[nodiscard]] const std::string& topic() const noexcept { return topic_; }

 private:
  friend class IpcSample;
  struct Impl;
  IpcSubscriber(std::unique_ptr<Impl> impl, std::string topic, const IpcSubscriberConfig& config);
  void release(const std::byte* payload) noexcept;
  [[nodiscard]] Result<std::optional<IpcSample>, IpcError> take_one() noexcept;
  std::unique_ptr<Impl> impl_;
  std::string topic_;
  IpcSubscriberConfig config_;
  IpcCounters counters_;
  bool first_ = true;
  std::uint64_t last_sequence_ = 0;
};

}  // namespace orthoflow::engine
