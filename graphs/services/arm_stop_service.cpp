// The arm's stop over iceoryx (arm_stop_service.hpp): the holder's listener and the requester.
#include "graphs/services/arm_stop_service.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstring>

#include "engine/ipc_runtime.hpp"

namespace orthoflow::graphs {
namespace {

constexpr engine::IpcPayloadType REQUEST_TYPE{engine::ARM_STOP_TYPE_ID, engine::ARM_STOP_VERSION};
constexpr engine::IpcPayloadType ACK_TYPE{engine::ARM_STOP_ACK_TYPE_ID, engine::ARM_STOP_VERSION};
// Acks are kept for late subscribers: a requester's subscriber may connect after the answer.
constexpr std::uint64_t ACK_HISTORY = 8;

template <class Pod>
void copy_text(char (&out)[64], std::string_view text) noexcept {
  const std::size_t n = std::min(text.size(), sizeof out - 1);
  std::memcpy(out, text.data(), n);
  out[n] = '\0';
}

std::string_view text_of(const char (&in)[64]) noexcept { return {in, ::strnlen(in, sizeof in)}; }

template <class Pod>
bool read_pod(const engine::IpcSample& sample, engine::IpcPayloadType type,
              const std::string& topic, Pod& out) noexcept {
  const auto bytes = sample.bytes();
  auto size = engine::check_payload_header(bytes, type, topic);
  if (!size || *size != sizeof(Pod) || bytes.size() < sizeof(Pod)) return false;
  std::memcpy(&out, bytes.data(), sizeof(Pod));
  return true;
}

Result<std::unique_ptr<engine::IpcPublisher>, std::string> make_publisher(
    const char* topic, engine::IpcPayloadType type, std::size_t bytes, std::uint64_t history) {
  auto pools = engine::query_roudi_pools(std::chrono::milliseconds(3000));
  if (!pools) return err(engine::to_string(pools.error()));
  auto t = engine::parse_topic(topic);
  auto p = engine::IpcPublisher::create(*t, {type, bytes, history, false}, *pools);
  if (!p) return err(engine::to_string(p.error()));
  return std::move(*p);
}

Result<std::unique_ptr<engine::IpcSubscriber>, std::string> make_subscriber(
    const char* topic, engine::IpcPayloadType type, std::uint64_t history) {
  auto t = engine::parse_topic(topic);
  auto s = engine::IpcSubscriber::create(*t, {type, engine::IpcPolicy::QUEUE, 16, history});
  if (!s) return err(engine::to_string(s.error()));
  return std::move(*s);
}

}  // namespace

std::int64_t steady_now_ns() noexcept {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

Result<std::unique_ptr<ArmStopListener>, std::string> ArmStopListener::start(Halt halt,
                                                                             std::string holder) {
  std::unique_ptr<ArmStopListener> l(new ArmStopListener());
  l->halt_ = std::move(halt);
  l->holder_ = std::move(holder);
  auto requests = make_subscriber(engine::ARM_STOP_TOPIC, REQUEST_TYPE, 0);
  if (!requests) return err(requests.error());
  auto acks =
      make_publisher(engine::ARM_STOP_ACK_TOPIC, ACK_TYPE, sizeof(engine::ArmStopAck), ACK_HISTORY);
  if (!acks) return err(acks.error());
  l->requests_ = std::move(*requests);
  l->acks_ = std::move(*acks);
  l->thread_ = std::thread([raw = l.get()] { raw->run(); });
  return l;
}

ArmStopListener::~ArmStopListener() {
  stop_.store(true);
  if (thread_.joinable()) thread_.join();
}

void ArmStopListener::run() noexcept {
  while (!stop_.load()) {
    auto sample = requests_->take();
    if (sample && sample->has_value()) {
      engine::ArmStopRequest request{};
      if (read_pod(**sample, REQUEST_TYPE, requests_->topic(), request)) serve(request);
      continue;  // drain the queue before sleeping
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}

void ArmStopListener::serve(const engine::ArmStopRequest& request) noexcept {
  if (request.target_pid != 0 && request.target_pid != static_cast<std::int32_t>(::getpid()))
    return;  // for another holder (another arm on this RouDi)
  const std::string_view reason = text_of(request.reason);
  const bool was_moving = halt_(reason.empty() ? std::string_view("a stop request") : reason);
  engine::ArmStopAck ack;
  ack.reset();
  ack.request_id = request.request_id;
  ack.request_ns = request.request_ns;
  ack.halted_ns = steady_now_ns();
  ack.requester_pid = request.requester_pid;
  ack.holder_pid = static_cast<std::int32_t>(::getpid());
  ack.was_moving = was_moving ? 1U : 0U;
  copy_text<engine::ArmStopAck>(ack.holder, holder_);
  (void)acks_->publish_copy({reinterpret_cast<const std::byte*>(&ack), sizeof ack});
  served_.fetch_add(1);
}

Result<ArmStopOutcome, std::string> request_arm_stop(std::string_view reason,
                                                     std::chrono::milliseconds timeout,
                                                     int target_pid) {
  auto acks = make_subscriber(engine::ARM_STOP_ACK_TOPIC, ACK_TYPE, ACK_HISTORY);
  if (!acks) return err(acks.error());
  auto requests =
      make_publisher(engine::ARM_STOP_TOPIC, REQUEST_TYPE, sizeof(engine::ArmStopRequest), 0);
  if (!requests) return err(requests.error());
  ArmStopOutcome outcome;
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  // A holder's subscriber is matched by RouDi's discovery (a few 10 ms): wait for it.
  while (!(*requests)->has_subscribers()) {
    if (std::chrono::steady_clock::now() > deadline) {
      outcome.status = ArmStopOutcome::Status::NO_LISTENER;
      return outcome;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  engine::ArmStopRequest request;
  request.reset();
  request.requester_pid = static_cast<std::int32_t>(::getpid());
  request.target_pid = target_pid;
  request.request_ns = steady_now_ns();
  request.request_id = static_cast<std::uint64_t>(request.request_ns) ^
                       (static_cast<std::uint64_t>(request.requester_pid) << 40U);
  copy_text<engine::ArmStopRequest>(request.reason, reason);
  outcome.request_ns = request.request_ns;
  if (auto sent =
          (*requests)->publish_copy({reinterpret_cast<const std::byte*>(&request), sizeof request});
      !sent)
    return err(engine::to_string(sent.error()));
  while (std::chrono::steady_clock::now() <= deadline) {
    auto sample = (*acks)->take();
    if (sample && sample->has_value()) {
      engine::ArmStopAck ack{};
      if (read_pod(**sample, ACK_TYPE, (*acks)->topic(), ack) &&
          ack.request_id == request.request_id && ack.requester_pid == request.requester_pid) {
        outcome.status = ArmStopOutcome::Status::STOPPED;
        outcome.was_moving = ack.was_moving != 0;
        outcome.holder_pid = ack.holder_pid;
        outcome.holder = std::string(text_of(ack.holder));
        outcome.halted_ns = ack.halted_ns;
        return outcome;
      }
      continue;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  outcome.status = ArmStopOutcome::Status::NO_ANSWER;
  return outcome;
}

}  // namespace orthoflow::graphs
