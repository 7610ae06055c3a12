// The table task's report (graphs/sessions/table_task_session.hpp): the plan and every move held
// against the world's ground truth (what was perceived and recognised, which object each move
// took, whether it arrived where planned). The loop itself is in table_task_session.cpp.
#include <algorithm>
#include <string>
#include <vector>

#include "graphs/sessions/task_session.hpp"

namespace orthoflow::graphs {

std::size_t TableTaskReport::arrived() const noexcept {
  return static_cast<std::size_t>(
      std::count_if(moves.begin(), moves.end(), [](const MoveReport& m) { return m.arrived; }));
}

std::size_t TableTaskReport::first_moves() const noexcept {
  return static_cast<std::size_t>(std::count_if(
      moves.begin(), moves.end(), [](const MoveReport& m) { return m.attempt == 1; }));
}

namespace {

constexpr double ARRIVED_M = 0.05;

}  // namespace

std::string TaskLoop::truth_near(const Vector3d& base_point) const {
  const simulation::Scene& scene = world_->scene();
  std::string best;
  double best_d = 0.06;
  for (std::size_t i = 0; i < scene.objects.size(); ++i) {
    const Vector3d c = to_base(world_->centre(i));
    const double d = (c - base_point).head<2>().norm();
    if (d < best_d) {
      best_d = d;
      best = simulation::category_name(scene.objects[i].model.category);
    }
  }
  return best;
}

void TaskLoop::plan_task() {
  std::vector<std::string> known;
  for (const learning::CategorySummary& c : learning_->learner().categories())
    known.emplace_back(c.label.view());
  if (auto ok = runner_->start(known); !ok) {
    report_.refused = ok.error();
    return;
  }
  for (const manipulation::SeenObject& s : runner_->seen()) {
    ++report_.perceived;
    if (!s.label.empty() && s.label == truth_near(s.centre)) ++report_.recognised;
  }
  for (const manipulation::StayRecord& s : runner_->stays()) {
    const auto it =
        std::find_if(runner_->seen().begin(), runner_->seen().end(),
                     [&](const manipulation::SeenObject& x) { return x.track == s.track; });
    report_.stays.push_back({s.track, s.label,
                             it == runner_->seen().end() ? std::string() : truth_near(it->centre),
                             s.reason});
  }
  for (std::size_t m = 0; m < runner_->moves().size(); ++m) {
    MoveReport r;
    r.truth = truth_near(runner_->planned()[m]);
    report_.moves.push_back(std::move(r));
  }
  copy_records();
}

void TaskLoop::grow_reports() {
  // The runner's retries (a failed move tried once more at the end) get a report each.
  while (report_.moves.size() < runner_->moves().size()) {
    MoveReport r;
    r.truth = report_.moves[runner_->moves()[report_.moves.size()].retry_of].truth;
    report_.moves.push_back(std::move(r));
  }
}

void TaskLoop::copy_records() {
  grow_reports();
  for (std::size_t m = 0; m < report_.moves.size(); ++m)
    static_cast<manipulation::MoveRecord&>(report_.moves[m]) = runner_->moves()[m];
}

void TaskLoop::move_started(std::size_t /*move*/, const manipulation::SeenObject& s) {
  grow_reports();
  target_object_ = -1;
  double best = 0.10;
  for (std::size_t i = 0; i < world_->scene().objects.size(); ++i) {
    const double d = (to_base(world_->centre(i)) - s.centre).head<2>().norm();
    if (d < best) {
      best = d;
      target_object_ = static_cast<int>(world_->scene().objects[i].id);
      target_start_ = to_base(world_->centre(i));
    }
  }
}

void TaskLoop::move_ended(std::size_t move) {
  MoveReport& r = report_.moves[move];
  const manipulation::MoveRecord& record = runner_->moves()[move];
  const int index =
      target_object_ >= 0 ? world_->find(static_cast<std::uint32_t>(target_object_)) : -1;
  if (index >= 0 && world_->held() != index) {
    const auto i = static_cast<std::size_t>(index);
    const Vector3d c = to_base(world_->centre(i));
    // Moved as planned: the object's own displacement is the plan's (spot minus the perceived
    // centre) within ARRIVED_M. (Its model origin is not its perceived centre: a mug's box holds
    // its handle.)
    const Vector2d planned = record.to - runner_->target_centre().head<2>();
    r.error_m = ((c - target_start_).head<2>() - planned).norm();
    r.arrived = world_->scene().objects[i].base_m == 0.0 && r.error_m < ARRIVED_M;
  }
}

}  // namespace orthoflow::graphs
