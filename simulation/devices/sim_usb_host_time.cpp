// SimUsbHost: simulated time. Events (iso transfer completions, the devices' scheduled faults) run
// in time order; every device is stepped whenever the clock moves. Every state change of a device
// happens at one simulated instant.
#include <algorithm>

#include "core/assert.hpp"
#include "simulation/devices/sim_usb_host.hpp"
#include "simulation/devices/sim_usb_host_state.hpp"

namespace orthoflow::simulation {

using drivers::UsbError;

Result<void, UsbError> SimUsbHost::handle_events(drivers::UsbTimeout timeout) {
  enforce_not_in_callback();
  if (timeout.count() < 0)
    return orthoflow::err(UsbError{UsbError::Code::INVALID_PARAM, 0, "handle_events"});
  const std::int64_t now = clock_->now_ns();
  std::int64_t target = now;
  if (timeout.count() > 0) {
    const std::int64_t deadline =
        now + std::chrono::duration_cast<std::chrono::nanoseconds>(timeout).count();
    target = std::clamp(next_event_ns(true), now, deadline);
  }
  run_until(target);
  return {};
}

void SimUsbHost::run_for(std::chrono::nanoseconds duration) {
  enforce_not_in_callback();
  OF_ENFORCE(duration.count() >= 0, "SimUsbHost::run_for: negative duration");
  run_until(clock_->now_ns() + duration.count());
}

void SimUsbHost::advance_clock(std::int64_t t_ns) noexcept {
  // A given clock may have been moved ahead by hand: events then run late, never backwards.
  if (t_ns > clock_->now_ns()) clock_->set_ns(t_ns);
  step_devices();
}

std::int64_t SimUsbHost::next_event_ns(bool waking_only) const noexcept {
  std::int64_t next = SIM_USB_NEVER;
  for (const auto& s : streams_) {
    if (s->alive && slots_[s->slot]->present) next = std::min(next, s->completion_ns());
  }
  for (const auto& slot : slots_) {
    const SimDeviceEvent event = slot->device->next_event(slot->present);
    if (!waking_only || event.wakes) next = std::min(next, event.at_ns);
  }
  return next;
}

bool SimUsbHost::run_next_event(std::int64_t limit_ns) {
  // Transfer completions first: on a tie they happened before the device's event.
  Stream* first = nullptr;
  for (const auto& s : streams_) {
    if (!s->alive || !slots_[s->slot]->present) continue;
    if (first == nullptr || s->completion_ns() < first->completion_ns()) first = s.get();
  }
  const std::int64_t next = next_event_ns(false);
  if (next > limit_ns) return false;
  advance_clock(next);
  if (first != nullptr && first->completion_ns() == next) {
    complete(*first);
    return true;
  }
  return run_device_event(next);
}

bool SimUsbHost::run_device_event(std::int64_t at_ns) {
  for (std::size_t k = 0; k < slots_.size(); ++k) {
    Slot& slot = *slots_[k];
    if (slot.device->next_event(slot.present).at_ns != at_ns) continue;
    switch (slot.device->take_event(at_ns, slot.present)) {
      case SimPlugAction::UNPLUG:
        unplug_device(k);
        break;
      case SimPlugAction::REPLUG:
        replug_device(k);
        break;
      case SimPlugAction::CANCEL_STREAMS:
        fail_streams(k, drivers::UsbPacketStatus::CANCELLED);
        break;
      case SimPlugAction::NONE:
        break;
    }
    return true;
  }
  return false;  // unreachable: the time came from one of the sources above
}

void SimUsbHost::run_until(std::int64_t target_ns) {
  while (run_next_event(target_ns)) {}
  advance_clock(target_ns);
}

bool SimUsbHost::run_while_alive(const Handle& h, std::int64_t target_ns) {
  // Stops at the unplug if the cable is pulled on the way: the transfer ends there.
  while (alive(h) && run_next_event(target_ns)) {}
  if (!alive(h)) return false;
  advance_clock(target_ns);
  return true;
}

}  // namespace orthoflow::simulation
