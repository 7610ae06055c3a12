#include "graphs/services/arm_state_feed.hpp"

#include <algorithm>
#include <cstring>

namespace orthoflow::graphs {

engine::ArmStatePayload arm_state_payload(const drivers::jaco::ArmSnapshot& s,
                                          std::int64_t stamp_ns,
                                          const manipulation::HeldObject& held) noexcept {
  namespace jaco = drivers::jaco;
  engine::ArmStatePayload p;
  p.reset();
  p.flags = (s.estop ? engine::ARM_ESTOP : 0U) | (s.fault ? engine::ARM_FAULT : 0U);
  p.arm_state = static_cast<std::int32_t>(s.arm_state);
  p.cycle = s.cycle;
  p.stamp_ns = stamp_ns;
  p.control = static_cast<std::uint32_t>(s.control);
  p.last_stop = static_cast<std::uint32_t>(s.last_stop);
  p.watchdog_stops = s.watchdog_stops;
  for (std::size_t j = 0; j < jaco::JOINTS; ++j) {
    p.joints_deg[j] = s.joints[j];
    p.velocity_deg_s[j] = s.velocity[j];
    p.currents_a[j] = s.currents[j];
  }
  for (std::size_t f = 0; f < jaco::FINGERS; ++f) p.fingers[f] = s.fingers[f];
  for (int i = 0; i < 3; ++i) {
    p.position_m[i] = s.pose.position[i];
    p.theta_rad[i] = s.pose.theta[i];
  }
  p.voltage_v = s.sensors.voltage_v;
  if (held.held()) {
    for (int k = 0; k < 3; ++k) {
      p.held_m[k] = held.a[k];
      p.held_m[3 + k] = held.b[k];
    }
    p.held_m[6] = held.radius_m;
  }
  return p;
}

void ArmStateChannel::write(const engine::ArmStatePayload& state) noexcept {
  std::array<std::uint64_t, WORDS> words;
  std::memcpy(words.data(), &state, sizeof state);
  const std::uint64_t n = written_.load(std::memory_order_relaxed);
  Entry& e = entries_[n % DEPTH];
  e.sequence.store(2 * n + 1, std::memory_order_relaxed);
  std::atomic_thread_fence(std::memory_order_release);
  for (std::size_t i = 0; i < WORDS; ++i) e.words[i].store(words[i], std::memory_order_relaxed);
  e.sequence.store(2 * n + 2, std::memory_order_release);
  written_.store(n + 1, std::memory_order_release);
}

std::size_t ArmStateChannel::drain(std::span<engine::ArmStatePayload> out) noexcept {
  const std::uint64_t written = written_.load(std::memory_order_acquire);
  std::uint64_t first = std::max(read_, written > DEPTH ? written - DEPTH : 0);
  if (written - first > out.size()) first = written - out.size();
  std::size_t count = 0;
  std::array<std::uint64_t, WORDS> words;
  for (std::uint64_t n = first; n < written; ++n) {
    const Entry& e = entries_[n % DEPTH];
    if (e.sequence.load(std::memory_order_acquire) != 2 * n + 2) continue;  // overwritten since
    for (std::size_t i = 0; i < WORDS; ++i) words[i] = e.words[i].load(std::memory_order_relaxed);
    std::atomic_thread_fence(std::memory_order_acquire);
    if (e.sequence.load(std::memory_order_relaxed) != 2 * n + 2) continue;  // torn: skip it
    std::memcpy(&out[count++], words.data(), sizeof(engine::ArmStatePayload));
  }
  read_ = written;
  return count;
}

Result<std::unique_ptr<IpcArmStateFeed>, std::string> IpcArmStateFeed::create(
    const std::string& topic) {
  auto parsed = engine::parse_topic(topic);
  if (!parsed) return err(engine::to_string(parsed.error()));
  engine::IpcSubscriberConfig config;
  config.type = {engine::ARM_STATE_TYPE_ID, engine::ARM_STATE_VERSION};
  config.policy = engine::IpcPolicy::QUEUE;
  config.depth = 64;
  config.history = 1;  // the publisher keeps its newest state for a late subscriber
  auto subscriber = engine::IpcSubscriber::create(*parsed, config);
  if (!subscriber) return err(engine::to_string(subscriber.error()));
  return std::unique_ptr<IpcArmStateFeed>(new IpcArmStateFeed(std::move(*subscriber)));
}

std::size_t IpcArmStateFeed::drain(std::span<engine::ArmStatePayload> out) noexcept {
  // Bounded: the queue holds at most 64 samples; a rejected one is released and counted.
  if (out.empty()) return 0;
  std::size_t count = 0;
  for (std::size_t i = 0; i < 2 * out.size() + 8; ++i) {
    auto taken = subscriber_->take();
    if (!taken) continue;            // refused by the header check (counted as rejected)
    if (!taken->has_value()) break;  // nothing more
    if ((**taken).bytes().size() < sizeof(engine::ArmStatePayload)) continue;
    if (count == out.size()) {  // more than fit: keep the newest
      std::move(out.begin() + 1, out.end(), out.begin());
      --count;
    }
    std::memcpy(&out[count++], (**taken).bytes().data(), sizeof(engine::ArmStatePayload));
  }
  return count;
}

std::uint64_t IpcArmStateFeed::received() const noexcept {
  return subscriber_->counters().samples.load(std::memory_order_relaxed);
}

std::uint64_t IpcArmStateFeed::rejected() const noexcept {
  return subscriber_->counters().rejected.load(std::memory_order_relaxed);
}

}  // namespace orthoflow::graphs
