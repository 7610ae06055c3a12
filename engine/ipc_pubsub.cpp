#include "engine/ipc_pubsub.hpp"

#include <cstring>

#include "iceoryx_posh/mepoo/chunk_header.hpp"
#include "iceoryx_posh/popo/untyped_publisher.hpp"
#include "iceoryx_posh/popo/untyped_subscriber.hpp"

namespace orthoflow::engine {

namespace {

// Builds an error without letting an allocation failure escape a noexcept frame-path function.
IpcError error_of(IpcError::Code code, const std::string& topic, const char* what,
                  std::uint64_t a = 0, std::uint64_t b = 0) noexcept {
  try {
    return IpcError{code, "topic " + topic + ": " + what + " (" + std::to_string(a) + ", " +
                              std::to_string(b) + ")"};
  } catch (...) { return IpcError{code, {}}; }
}

bool valid_part(const std::string& part) {
  if (part.empty() || part.size() > 100) return false;
  for (char c : part) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '_' || c == '-' || c == '.';
    if (!ok) return false;
  }
  return true;
}

iox::capro::ServiceDescription service_of(const IpcTopic& topic) {
  using Id = iox::capro::IdString_t;
  return {Id(iox::cxx::TruncateToCapacity, topic.service.c_str()),
          Id(iox::cxx::TruncateToCapacity, topic.instance.c_str()),
          Id(iox::cxx::TruncateToCapacity, topic.event.c_str())};
}

}  // namespace

Result<IpcTopic, IpcError> parse_topic(const std::string& text) {
  IpcTopic topic;
  const auto first = text.find('/');
  const auto second = first == std::string::npos ? std::string::npos : text.find('/', first + 1);
  if (second != std::string::npos) {
    topic = IpcTopic{text.substr(0, first), text.substr(first + 1, second - first - 1),
                     text.substr(second + 1)};
  }
  if (second == std::string::npos || !valid_part(topic.service) || !valid_part(topic.instance) ||
      !valid_part(topic.event)) {
    return err(IpcError{IpcError::Code::BAD_TOPIC,
                        "topic '" + text +
                            "': expected service/instance/event, e.g. "
                            "orthoflow/kinect0/frames, each 1..100 of [A-Za-z0-9_.-]"});
  }
  return topic;
}

Result<std::uint64_t, IpcError> check_payload_header(std::span<const std::byte> bytes,
                                                     IpcPayloadType type,
                                                     const std::string& topic) {
  if (bytes.size() < PAYLOAD_HEADER_BYTES) {
    return err(error_of(IpcError::Code::BAD_SIZE, topic,
                        "payload shorter than its header (bytes, needed)", bytes.size(),
                        PAYLOAD_HEADER_BYTES));
  }
  std::uint32_t type_id = 0;
  std::uint16_t version = 0;
  std::uint64_t payload_bytes = 0;
  std::memcpy(&type_id, bytes.data(), sizeof(type_id));
  std::memcpy(&version, bytes.data() + 4, sizeof(version));
  std::memcpy(&payload_bytes, bytes.data() + PAYLOAD_BYTES_OFFSET, sizeof(payload_bytes));
  if (type_id != type.type_id) {
    return err(error_of(IpcError::Code::WRONG_TYPE, topic,
                        "payload type id differs (found, expected)", type_id, type.type_id));
  }
  if (version != type.version) {
    return err(error_of(IpcError::Code::WRONG_VERSION, topic,
                        "payload version differs (found, expected)", version, type.version));
  }
  if (payload_bytes < PAYLOAD_HEADER_BYTES || payload_bytes > bytes.size()) {
    return err(error_of(IpcError::Code::BAD_SIZE, topic,
                        "payload_bytes outside the chunk (payload_bytes, chunk)", payload_bytes,
                        bytes.size()));
  }
  return payload_bytes;
}

// ---------------------------------------------------------------------------------------------
struct IpcPublisher::Impl {
  iox::popo::UntypedPublisher publisher;
};

IpcPublisher::IpcPublisher(std::unique_ptr<Impl> impl, std::string topic,
                           const IpcPublisherConfig& config)
    : impl_(std::move(impl)), topic_(std::move(topic)), config_(config) {}
IpcPublisher::~IpcPublisher() = default;

Result<std::unique_ptr<IpcPublisher>, IpcError> IpcPublisher::create(
    const IpcTopic& topic, const IpcPublisherConfig& config, const IpcPools& pools) {
  if (!ipc_runtime_ready()) {
    return err(IpcError{IpcError::Code::ROUDI_UNREACHABLE,
                        "publisher " + topic.str() + ": IPC runtime not initialised"});
  }
  if (config.max_payload_bytes < PAYLOAD_HEADER_BYTES) {
    return err(IpcError{IpcError::Code::BAD_SIZE,
                        "publisher " + topic.str() + ": max payload below 56 B header"});
  }
  if (auto fits = check_pool_fits(pools, config.max_payload_bytes, PAYLOAD_ALIGNMENT,
                                  "publisher " + topic.str());
      !fits) {
    return err(fits.error());
  }
  iox::popo::PublisherOptions options;
  options.historyCapacity = config.history;
  options.subscriberTooSlowPolicy = config.lossless
                                        ? iox::popo::ConsumerTooSlowPolicy::WAIT_FOR_CONSUMER
                                        : iox::popo::ConsumerTooSlowPolicy::DISCARD_OLDEST_DATA;
  auto impl =
      std::unique_ptr<Impl>(new Impl{iox::popo::UntypedPublisher(service_of(topic), options)});
  return std::unique_ptr<IpcPublisher>(new IpcPublisher(std::move(impl), topic.str(), config));
}

Result<std::span<std::byte>, IpcError> IpcPublisher::loan(std::size_t bytes) noexcept {
  if (bytes < PAYLOAD_HEADER_BYTES || bytes > config_.max_payload_bytes) {
    return err(error_of(IpcError::Code::BAD_SIZE, topic_,
                        "loan outside [56, max_payload_bytes] (bytes, max)", bytes,
                        config_.max_payload_bytes));
  }
  auto loaned = impl_->publisher.loan(static_cast<std::uint32_t>(bytes), PAYLOAD_ALIGNMENT);
  if (loaned.has_error()) {
    counters_.loan_failures.fetch_add(1, std::memory_order_relaxed);
    const bool parallel =
        loaned.get_error() == iox::popo::AllocationError::TOO_MANY_CHUNKS_ALLOCATED_IN_PARALLEL;
    return err(error_of(parallel ? IpcError::Code::TOO_MANY_LOANS : IpcError::Code::POOL_EXHAUSTED,
                        topic_,
                        parallel ? "more than 8 chunks loaned at once (bytes, error)"
                                 : "no free chunk in RouDi's pools (bytes, error)",
                        bytes, static_cast<std::uint64_t>(loaned.get_error())));
  }
  return std::span<std::byte>(static_cast<std::byte*>(loaned.value()), bytes);
}

Result<void, IpcError> IpcPublisher::publish(std::span<std::byte> loaned) noexcept {
  auto checked = check_payload_header(loaned, config_.type, topic_);
  if (!checked) {
    impl_->publisher.release(loaned.data());
    counters_.rejected.fetch_add(1, std::memory_order_relaxed);
    return err(checked.error());
  }
  impl_->publisher.publish(loaned.data());
  counters_.samples.fetch_add(1, std::memory_order_relaxed);
  return {};
}

void IpcPublisher::release(std::span<std::byte> loaned) noexcept {
  impl_->publisher.release(loaned.data());
}

Result<void, IpcError> IpcPublisher::publish_copy(std::span<const std::byte> payload) noexcept {
  auto checked = check_payload_header(payload, config_.type, topic_);
  if (!checked) {
    counters_.rejected.fetch_add(1, std::memory_order_relaxed);
    return err(checked.error());
  }
  auto chunk = loan(static_cast<std::size_t>(*checked));
  if (!chunk) return err(chunk.error());
  std::memcpy(chunk->data(), payload.data(), chunk->size());
  return publish(*chunk);
}

bool IpcPublisher::has_subscribers() const noexcept { return impl_->publisher.hasSubscribers(); }

// ---------------------------------------------------------------------------------------------
IpcSample::IpcSample(IpcSample&& other) noexcept
    : owner_(std::exchange(other.owner_, nullptr)),
      bytes_(other.bytes_),
      sequence_(other.sequence_) {}

IpcSample& IpcSample::operator=(IpcSample&& other) noexcept {
  if (this != &other) {
    reset();
    owner_ = std::exchange(other.owner_, nullptr);
    bytes_ = other.bytes_;
    sequence_ = other.sequence_;
  }
  return *this;
}

IpcSample::~IpcSample() { reset(); }

void IpcSample::reset() noexcept {
  if (owner_ != nullptr) owner_->release(bytes_.data());
  owner_ = nullptr;
  bytes_ = {};
}

struct IpcSubscriber::Impl {
  iox::popo::UntypedSubscriber subscriber;
};

IpcSubscriber::IpcSubscriber(std::unique_ptr<Impl> impl, std::string topic,
                             const IpcSubscriberConfig& config)
    : impl_(std::move(impl)), topic_(std::move(topic)), config_(config) {}
IpcSubscriber::~IpcSubscriber() = default;

Result<std::unique_ptr<IpcSubscriber>, IpcError> IpcSubscriber::create(
    const IpcTopic& topic, const IpcSubscriberConfig& config) {
  if (!ipc_runtime_ready()) {
    return err(IpcError{IpcError::Code::ROUDI_UNREACHABLE,
                        "subscriber " + topic.str() + ": IPC runtime not initialised"});
  }
  if (config.depth < 1 || config.depth > iox::popo::SubscriberChunkQueueData_t::MAX_CAPACITY) {
    return err(IpcError{IpcError::Code::BAD_TOPIC,
                        "subscriber " + topic.str() + ": depth must be in 1..256"});
  }
  iox::popo::SubscriberOptions options;
  options.queueCapacity = config.policy == IpcPolicy::LATEST ? 1U : config.depth;
  options.historyRequest = config.history;
  options.queueFullPolicy = config.policy == IpcPolicy::LOSSLESS
                                ? iox::popo::QueueFullPolicy::BLOCK_PRODUCER
                                : iox::popo::QueueFullPolicy::DISCARD_OLDEST_DATA;
  auto impl =
      std::unique_ptr<Impl>(new Impl{iox::popo::UntypedSubscriber(service_of(topic), options)});
  return std::unique_ptr<IpcSubscriber>(new IpcSubscriber(std::move(impl), topic.str(), config));
}

void IpcSubscriber::release(const std::byte* payload) noexcept {
  impl_->subscriber.release(payload);
}

bool IpcSubscriber::subscribed() const noexcept {
  return impl_->subscriber.getSubscriptionState() == iox::SubscribeState::SUBSCRIBED;
}

Result<std::optional<IpcSample>, IpcError> IpcSubscriber::take_one() noexcept {
  auto taken = impl_->subscriber.take();
  if (taken.has_error()) {
    if (taken.get_error() == iox::popo::ChunkReceiveResult::NO_CHUNK_AVAILABLE)
      return std::optional<IpcSample>{};
    return err(error_of(IpcError::Code::TOO_MANY_LOANS, topic_,
                        "more than 256 chunks held (held, max)", 256, 256));
  }
  const void* payload = taken.value();
  const auto* header = iox::mepoo::ChunkHeader::fromUserPayload(payload);
  const std::uint64_t sequence = header->sequenceNumber();
  // The publisher numbers its chunks 0, 1, 2, ...: a gap is chunks iceoryx discarded for us (queue
  // full). A smaller number means a new publisher; its history is not counted as lost.
  if (!first_ && sequence > last_sequence_ + 1) {
    counters_.dropped.fetch_add(sequence - last_sequence_ - 1, std::memory_order_relaxed);
  }
  first_ = false;
  last_sequence_ = sequence;
  const std::span<const std::byte> bytes(static_cast<const std::byte*>(payload),
                                         header->userPayloadSize());
  auto checked = check_payload_header(bytes, config_.type, topic_);
  if (!checked) {
    impl_->subscriber.release(payload);
    counters_.rejected.fetch_add(1, std::memory_order_relaxed);
    return err(checked.error());
  }
  IpcSample sample;
  sample.owner_ = this;
  sample.bytes_ = bytes.first(static_cast<std::size_t>(*checked));
  sample.sequence_ = sequence;
  counters_.samples.fetch_add(1, std::memory_order_relaxed);
  return std::optional<IpcSample>(std::move(sample));
}

Result<std::optional<IpcSample>, IpcError> IpcSubscriber::take() noexcept {
  auto next = take_one();
  if (config_.policy != IpcPolicy::LATEST) return next;
  // Latest wins: anything newer replaces what we hold; the replaced sample counts as a drop.
  while (next && next->has_value() && impl_->subscriber.hasData()) {
    auto newer = take_one();
    if (!newer || !newer->has_value()) break;
    counters_.dropped.fetch_add(1, std::memory_order_relaxed);
    next = std::move(newer);
  }
  return next;
}

}  // namespace orthoflow::engine
