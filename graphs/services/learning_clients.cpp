// The learning channel's plumbing in the LearningService (graphs/services/learning_service.hpp):
// senders connect and send, the recognise node polls and acknowledges, acknowledgements reach the
// sender that asked.
#include <mutex>

#include "graphs/services/learning_service.hpp"

namespace orthoflow::graphs {

std::unique_ptr<LearningClient> LearningService::connect() {
  const std::lock_guard senders(senders_);
  for (std::uint32_t i = 0; i < clients_.size(); ++i) {
    ClientSlot& slot = clients_[i];
    if (slot.active.load()) continue;
    {
      const std::lock_guard producers(slot.lock);
      slot.acks.clear();  // acks of an earlier client of this slot are not this one's
    }
    slot.active.store(true);
    return std::unique_ptr<LearningClient>(new LearningClient(*this, i));
  }
  return nullptr;
}

void LearningService::disconnect(std::uint32_t slot) noexcept {
  clients_[slot].active.store(false);
}

std::uint64_t LearningService::enqueue(LearningCommand command) noexcept {
  const std::lock_guard senders(senders_);
  if (!commands_.try_push(command)) {
    commands_dropped_.fetch_add(1);
    return 0;
  }
  return command.sequence;
}

bool LearningService::poll(LearningCommand& command) noexcept { return commands_.try_pop(command); }

void LearningService::acknowledge(const LearningAck& ack) noexcept {
  if (ack.sender >= clients_.size() || !clients_[ack.sender].active.load()) {
    acks_dropped_.fetch_add(1);
    return;
  }
  ClientSlot& slot = clients_[ack.sender];
  const std::lock_guard producers(slot.lock);
  if (!slot.acks.try_push(ack)) acks_dropped_.fetch_add(1);
}

LearningClient::~LearningClient() { service_.disconnect(slot_); }

std::uint64_t LearningClient::send(LearningCommand command) noexcept {
  command.sender = slot_;
  command.sequence = next_sequence_;
  const std::uint64_t queued = service_.enqueue(command);
  if (queued != 0) ++next_sequence_;
  return queued;
}

bool LearningClient::poll(LearningAck& ack) noexcept {
  return service_.clients_[slot_].acks.try_pop(ack);
}

}  // namespace orthoflow::graphs
