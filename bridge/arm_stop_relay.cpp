// The DDS bridge's arm stop (arm_stop_relay.hpp).
#include "bridge/arm_stop_relay.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstring>

#include "engine/arm_stop_payload.hpp"

namespace orthoflow::bridge {
namespace {

constexpr engine::IpcPayloadType REQUEST_TYPE{engine::ARM_STOP_TYPE_ID, engine::ARM_STOP_VERSION};
constexpr engine::IpcPayloadType ACK_TYPE{engine::ARM_STOP_ACK_TYPE_ID, engine::ARM_STOP_VERSION};

}  // namespace

Result<std::unique_ptr<ArmStopRelay>, std::string> ArmStopRelay::open(
    const engine::IpcPools& pools) {
  std::unique_ptr<ArmStopRelay> r(new ArmStopRelay());
  auto requests =
      engine::IpcPublisher::create(*engine::parse_topic(engine::ARM_STOP_TOPIC),
                                   {REQUEST_TYPE, sizeof(engine::ArmStopRequest), 0, false}, pools);
  if (!requests) return err("arm stop: " + engine::to_string(requests.error()));
  auto acks = engine::IpcSubscriber::create(*engine::parse_topic(engine::ARM_STOP_ACK_TOPIC),
                                            {ACK_TYPE, engine::IpcPolicy::QUEUE, 16, 0});
  if (!acks) return err("arm stop acks: " + engine::to_string(acks.error()));
  r->requests_ = std::move(*requests);
  r->acks_ = std::move(*acks);
  return r;
}

void ArmStopRelay::answer(RosEndpoints& ros, bool stopped, const Pending& p, const char* problem,
                          bool was_moving, int holder_pid, const char* holder, double ms) {
  RosArmStopAck ack{};
  ack.stopped = stopped;
  ack.was_moving = was_moving;
  ack.holder_pid = holder_pid;
  ack.holder = const_cast<char*>(holder);  // DDS serialises it during the write
  ack.reason = const_cast<char*>(p.reason.data());
  ack.problem = const_cast<char*>(problem);
  ack.request_to_halt_ms = ms;
  (void)ros.write_arm_stop_ack(ack);
}

std::size_t ArmStopRelay::pump(RosEndpoints& ros, std::int64_t now_ns) {
  std::size_t work = ros.take_arm_stops(16, [&](std::string_view reason) {
    ++stops_in_;
    Pending p;
    const std::size_t n = std::min(reason.size(), p.reason.size() - 1);
    std::memcpy(p.reason.data(), reason.data(), n);
    if (!requests_->has_subscribers())
      return answer(ros, false, p, "no process holding an arm listens for stops");
    auto slot =
        std::find_if(pending_.begin(), pending_.end(), [](const Pending& q) { return q.id == 0; });
    if (slot == pending_.end()) return answer(ros, false, p, "busy: 16 stops wait for answers");
    engine::ArmStopRequest request;
    request.reset();
    request.request_id = next_id_++;
    request.requester_pid = static_cast<std::int32_t>(::getpid());
    request.request_ns = now_ns;
    std::memcpy(request.reason, p.reason.data(), n);
    if (!requests_->publish_copy({reinterpret_cast<const std::byte*>(&request), sizeof request}))
      return answer(ros, false, p, "iceoryx had no chunk for the stop: send again");
    p.id = request.request_id;
    p.sent_ns = now_ns;
    *slot = p;
  });
  for (int i = 0; i < 16; ++i) {
    auto taken = acks_->take();
    if (!taken) continue;
    if (!taken->has_value()) break;
    ++work;
    const auto bytes = (*taken)->bytes();
    if (!engine::check_payload_header(bytes, ACK_TYPE, acks_->topic()) ||
        bytes.size() < sizeof(engine::ArmStopAck))
      continue;
    engine::ArmStopAck ack{};
    std::memcpy(&ack, bytes.data(), sizeof ack);
    if (ack.requester_pid != static_cast<std::int32_t>(::getpid())) continue;  // another's
    for (Pending& p : pending_) {
      if (p.id == 0 || p.id != ack.request_id) continue;
      ack.holder[sizeof ack.holder - 1] = '\0';
      answer(ros, true, p, "", ack.was_moving != 0, ack.holder_pid, ack.holder,
             1e-6 * static_cast<double>(ack.halted_ns - ack.request_ns));
      ++confirmed_;
      p.id = 0;
    }
  }
  for (Pending& p : pending_) {
    if (p.id != 0 && now_ns - p.sent_ns > ANSWER_TIMEOUT_NS) {
      answer(ros, false, p, "the process holding the arm did not confirm the stop within 2 s");
      p.id = 0;
    }
  }
  return work;
}

}  // namespace orthoflow::bridge
