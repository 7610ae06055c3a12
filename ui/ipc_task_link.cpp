#include "ui/ipc_task_link.hpp"

#include "graphs/services/arm_stop_service.hpp"

#include <chrono>

#include "engine/ipc_pubsub.hpp"
#include "engine/ipc_runtime.hpp"
#include "ui/backend_support.hpp"
#include "ui/background_thread.hpp"
#include "ui/ipc_backend.hpp"

namespace orthoflow::ui {

namespace {

using Clock = std::chrono::steady_clock;

std::int64_t now_ns() { return Clock::now().time_since_epoch().count(); }

}  // namespace

Result<std::unique_ptr<IpcTaskLink>, std::string> IpcTaskLink::open(const std::string& graph) {
  auto status_topic = engine::parse_topic(graphs::task_status_topic(graph));
  auto commands_topic = engine::parse_topic(graphs::task_commands_topic(graph));
  if (!status_topic || !commands_topic) return err("bad graph name '" + graph + "'");
  auto status = engine::IpcSubscriber::create(
      *status_topic,
      {{graphs::TASK_STATUS_TYPE_ID, graphs::TASK_IPC_VERSION}, engine::IpcPolicy::LATEST, 1, 1});
  if (!status) return err(engine::to_string(status.error()));
  auto pools = engine::query_roudi_pools(std::chrono::milliseconds(2000));
  if (!pools) return err(engine::to_string(pools.error()));
  auto commands =
      engine::IpcPublisher::create(*commands_topic,
                                   {{graphs::TASK_COMMAND_TYPE_ID, graphs::TASK_IPC_VERSION},
                                    sizeof(graphs::TaskCommandPayload),
                                    0,
                                    false},
                                   *pools);
  if (!commands) return err(engine::to_string(commands.error()));
  return std::unique_ptr<IpcTaskLink>(new IpcTaskLink(std::move(*status), std::move(*commands)));
}

IpcTaskLink::IpcTaskLink(std::unique_ptr<engine::IpcSubscriber> status,
                         std::unique_ptr<engine::IpcPublisher> commands)
    : status_in_(std::move(status)),
      commands_out_(std::move(commands)),
      client_id_(random_client_id()) {
  poller_ = std::thread([this] { poll(); });
}

IpcTaskLink::~IpcTaskLink() {
  stop_.store(true);
  poller_.join();
}

void IpcTaskLink::poll() noexcept {
  make_this_thread_background();
  while (!stop_.load() && !engine::ipc_roudi_lost()) {
    try {
      auto taken = status_in_->take();
      if (!taken) {
        rejected_.fetch_add(1, std::memory_order_relaxed);
      } else if (taken->has_value()) {
        auto decoded = graphs::decode_task_status((*taken)->bytes());
        if (!decoded) {
          rejected_.fetch_add(1, std::memory_order_relaxed);
        } else {
          std::lock_guard<std::mutex> guard(state_lock_);
          newest_ = std::move(*decoded);
          newest_at_ns_ = now_ns();
          arrived_.notify_all();
        }
      }
    } catch (const std::exception&) {  // out of memory for a message: keep the last status
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
}

std::optional<TaskView> IpcTaskLink::view() const {
  std::lock_guard<std::mutex> guard(state_lock_);
  const std::int64_t now = now_ns();
  if (!newest_ || now - newest_at_ns_ >= STALE_AFTER_NS) return std::nullopt;
  const std::int64_t age = newest_->published_ns > 0 && newest_->published_ns <= now
                               ? now - newest_->published_ns
                               : now - newest_at_ns_;
  return TaskView{*newest_, age / 1'000'000};
}

TaskReply IpcTaskLink::send(const graphs::TaskCommand& command, int timeout_ms) {
  TaskReply reply;
  std::uint64_t request = 0;
  {
    std::lock_guard<std::mutex> guard(send_lock_);
    if (!commands_out_->has_subscribers()) {
      reply.status = TaskReply::Status::NO_TASK_PROCESS;
      return reply;
    }
    request = next_request_++;
    graphs::TaskCommandPayload wire;
    if (!graphs::encode_task_command(command, client_id_, request, wire)) {
      reply.status = TaskReply::Status::INVALID;
      return reply;
    }
    if (!commands_out_->publish_copy({reinterpret_cast<const std::byte*>(&wire), sizeof wire})) {
      reply.status = TaskReply::Status::NO_TASK_PROCESS;
      return reply;
    }
  }
  std::unique_lock<std::mutex> lock(state_lock_);
  const bool answered = arrived_.wait_for(lock, std::chrono::milliseconds(timeout_ms), [&] {
    return newest_ && newest_->client == client_id_ && newest_->request == request;
  });
  if (answered) {
    reply.status = TaskReply::Status::ANSWERED;
    reply.answer = *newest_;
  }
  return reply;
}

ArmStopReply IpcTaskLink::stop_arm(int timeout_ms) {
  ArmStopReply reply;
  auto outcome = graphs::request_arm_stop("web view", std::chrono::milliseconds(timeout_ms));
  if (!outcome) return reply;  // the topics could not be made: as good as no answer
  using S = graphs::ArmStopOutcome::Status;
  reply.status = outcome->status == S::STOPPED       ? ArmStopReply::Status::STOPPED
                 : outcome->status == S::NO_LISTENER ? ArmStopReply::Status::NO_HOLDER
                                                     : ArmStopReply::Status::TIMEOUT;
  reply.was_moving = outcome->was_moving;
  reply.holder_pid = outcome->holder_pid;
  reply.holder = outcome->holder;
  reply.request_to_halt_ms = 1e-6 * static_cast<double>(outcome->halted_ns - outcome->request_ns);
  return reply;
}

}  // namespace orthoflow::ui
