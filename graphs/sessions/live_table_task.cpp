#include "graphs/sessions/live_table_task.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "graphs/services/arm_state_feed.hpp"
#include "manipulation/grasp_planner.hpp"

namespace orthoflow::graphs {

namespace jaco = drivers::jaco;
using manipulation::TableTaskRunner;

void seen_objects(const engine::ObjectListPayload& list, const Eigen::Isometry3d& base_from_camera,
                  const manipulation::SupportPlane& table,
                  std::vector<manipulation::SeenObject>& out) {
  out.clear();
  const std::uint32_t count = std::min(list.count, engine::OBJECT_LIST_CAPACITY);
  for (std::uint32_t k = 0; k < count; ++k) {
    const engine::ObjectEntry& e = list.objects[k];
    if ((e.flags & engine::OBJECT_DESCRIBED) == 0U) continue;
    // Another process wrote it: a frame or box that is not finite, or a box not in (0, 2 m), is no
    // object to plan with.
    const bool finite = std::all_of(std::begin(e.frame), std::end(e.frame),
                                    [](float v) { return std::isfinite(v); }) &&
                        std::all_of(std::begin(e.bbox), std::end(e.bbox), [](float v) {
                          return std::isfinite(v) && v > 0.0F && v < 2.0F;
                        });
    if (!finite) continue;
    manipulation::SeenObject s;
    s.track = static_cast<std::uint32_t>(e.track_id);
    s.label = e.unknown != 0U ? std::string() : std::string(e.label.view());
    std::array<float, 16> f{};
    std::copy(std::begin(e.frame), std::end(e.frame), f.begin());
    s.box = manipulation::upright_box(
        manipulation::object_box_in_base(base_from_camera, f, {e.bbox[0], e.bbox[1], e.bbox[2]}),
        table);
    s.centre = s.box.base_from_object.translation();
    out.push_back(std::move(s));
  }
}

LiveTableTask::LiveTableTask(LiveTaskSettings settings, LiveTaskPorts ports)
    : settings_(std::move(settings)), ports_(std::move(ports)) {}

bool LiveTableTask::running() const noexcept {
  return runner_ && runner_->state() != TableTaskRunner::State::FINISHED;
}

void LiveTableTask::on_objects(const engine::ObjectListPayload& list) {
  seen_objects(list, settings_.options.base_from_camera, settings_.options.job.grasp.table, seen_);
  seen_stamp_ns_ = list.host_stamp_ns;
  new_objects_ = true;
  if (runner_) runner_->on_objects(seen_, seen_stamp_ns_);
}

TaskAnswer LiveTableTask::command(const RemoteTaskCommand& c, std::int64_t now_ns) {
  if (c.command.kind == TaskCommand::Kind::STOP) {
    if (!running()) {
      answer(c.client, c.request, TaskAnswer::REFUSED, "no task is running", now_ns);
      return TaskAnswer::REFUSED;
    }
    runner_->request_stop(now_ns, "stopped by a stop command", ports_.submit);
    answer(c.client, c.request, TaskAnswer::STOPPING, "", now_ns);
    return TaskAnswer::STOPPING;
  }
  if (running()) {
    answer(c.client, c.request, TaskAnswer::REFUSED,
           std::string("a task is running: ") + manipulation::to_string(task_), now_ns);
    return TaskAnswer::REFUSED;
  }
  if (seen_stamp_ns_ == 0 || now_ns - seen_stamp_ns_ > settings_.fresh_objects_ns) {
    answer(c.client, c.request, TaskAnswer::REFUSED, "no fresh objects from the graph", now_ns);
    return TaskAnswer::REFUSED;
  }
  const jaco::ArmSnapshot arm = ports_.snapshot();
  if (arm.fault || arm.estop) {
    answer(c.client, c.request, TaskAnswer::REFUSED,
           arm.estop ? "the emergency stop is pulled" : "the arm reports a fault", now_ns);
    return TaskAnswer::REFUSED;
  }
  manipulation::TableTaskOptions options = settings_.options;
  options.task = c.command.task;
  if (c.command.task == manipulation::TableTaskKind::SERVE_A_MEAL) options.bring = c.command.bring;
  runner_.emplace(std::move(options));
  runner_->on_objects(seen_, seen_stamp_ns_);
  runner_->on_arm_pose(arm.joints);
  task_ = c.command.task;
  const std::vector<std::string> known = ports_.known ? ports_.known() : std::vector<std::string>{};
  if (auto ok = runner_->start(known); !ok) {
    runner_.reset();
    answer(c.client, c.request, TaskAnswer::REFUSED, ok.error(), now_ns);
    return TaskAnswer::REFUSED;
  }
  new_objects_ = true;  // the first move starts at the next tick
  answer(c.client, c.request, TaskAnswer::STARTED, "", now_ns);
  return TaskAnswer::STARTED;
}

void LiveTableTask::invalid(const TaskCommandProblem& problem, std::int64_t now_ns) {
  answer(problem.client, problem.request, TaskAnswer::INVALID, problem.message, now_ns);
}

void LiveTableTask::answer(std::uint64_t client, std::uint64_t request, TaskAnswer a,
                           std::string message, std::int64_t now_ns) {
  client_ = client;
  request_ = request;
  answer_ = a;
  message_ = std::move(message);
  publish(now_ns);
}

void LiveTableTask::halted(const std::string& why, std::int64_t now_ns) {
  if (!running()) return;
  runner_->request_stop(now_ns, "halted: " + why, ports_.submit);
  answer(client_, request_, TaskAnswer::STOPPING, "halted: " + why, now_ns);
}

void LiveTableTask::tick(std::int64_t now_ns) {
  const jaco::ArmSnapshot arm = ports_.snapshot();
  manipulation::HeldObject held;
  if (runner_) {
    if (new_objects_) {
      runner_->on_arm_pose(arm.joints);
      runner_->step(now_ns, arm, ports_.submit);
    }
    if (runner_->cycle(now_ns, arm, ports_.submit) && ports_.keep_alive) ports_.keep_alive();
    runner_->finish_step(now_ns);
    (void)runner_->held(held);
  }
  new_objects_ = false;
  if (ports_.publish_state) ports_.publish_state(arm_state_payload(arm, now_ns, held));
  const TaskState state = status_state();
  if (state != published_state_ && state == TaskState::FINISHED) message_ = runner_->stopped();
  if (state != published_state_ || now_ns - last_status_ns_ >= settings_.status_period_ns)
    publish(now_ns);
}

TaskState LiveTableTask::status_state() const noexcept {
  return !runner_ ? TaskState::IDLE : running() ? TaskState::RUNNING : TaskState::FINISHED;
}

TaskStatus LiveTableTask::status(std::int64_t now_ns) const {
  TaskStatus s;
  s.state = status_state();
  s.task = task_;
  s.client = client_;
  s.request = request_;
  s.answer = answer_;
  s.published_ns = now_ns;
  s.message = message_;
  if (runner_) {
    s.moves = static_cast<std::uint32_t>(runner_->moves().size());
    s.move = static_cast<std::uint32_t>(std::min(runner_->move_index(), runner_->moves().size()));
    s.done = static_cast<std::uint32_t>(
        std::count_if(runner_->moves().begin(), runner_->moves().begin() + s.move,
                      [](const manipulation::MoveRecord& m) { return m.done; }));
    s.phase = runner_->manager().phase();
  }
  return s;
}

void LiveTableTask::publish(std::int64_t now_ns) {
  last_status_ns_ = now_ns;
  published_state_ = status_state();
  if (ports_.publish_status) ports_.publish_status(status(now_ns));
}

}  // namespace orthoflow::graphs
