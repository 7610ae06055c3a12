// The table-task runner's view of the table (manipulation/table_task_runner.hpp): finding a move's
// object again among perception's newest objects, telling the target and its pieces from the
// bystanders, the other objects as obstacles, the arm's occlusion, and whether two moves may swap
// spots. Its life cycle is in table_task_runner.cpp, its job search in table_task_move.cpp.
#include <algorithm>
#include <span>
#include <vector>

#include "manipulation/table_task_limits.hpp"
#include "manipulation/table_task_runner.hpp"

namespace orthoflow::manipulation {

using Eigen::Vector2d;
using Eigen::Vector3d;

std::size_t TableTaskRunner::fill_obstacles(const SeenObject* target, const Vector3d& hand,
                                            bool holding) {
  std::size_t used = 0;
  for (const SeenObject& o : seen_) {
    if (!is_target(o, target) && !(holding && (o.centre - hand).norm() < HAND_HIDES_M))
      used = add_spheres(o, used);
  }
  return used;
}

const SeenObject* TableTaskRunner::find_seen(std::uint32_t track, const Vector3d& near,
                                             const std::string& label, double same_label_m,
                                             double any_m, bool not_bystanders) const {
  const SeenObject* best = nullptr;
  double best_d = 0.0;
  bool by_track = false;
  for (const SeenObject& o : seen_) {
    if (not_bystanders && a_bystander(o.centre)) continue;
    const double d = (o.centre - near).norm();
    // By its track first (of the pieces with it, the nearest); else by distance.
    if (o.track == track) {
      if (!by_track || d < best_d) {
        best = &o;
        best_d = d;
      }
      by_track = true;
    } else if (!by_track && (d < any_m || (d < same_label_m && o.label == label)) &&
               (best == nullptr || d < best_d)) {
      best = &o;
      best_d = d;
    }
  }
  return best;
}

bool TableTaskRunner::a_bystander(const Vector3d& centre) const noexcept {
  // Standing (not risen with the hand) and nearer to where another object stood when the move
  // started than to where the target stood: that other object, whatever its track or label.
  const Vector3d& up = options_.job.grasp.table.normal;
  if ((centre - target_centre_).dot(up) > options_.limits.target_moved_m) return false;
  const double to_target = (centre - target_centre_).norm();
  for (std::size_t k = 0; k < bystander_count_; ++k) {
    if ((centre - bystanders_[k]).norm() < to_target) return true;
  }
  return false;
}

const SeenObject* TableTaskRunner::current_target() const {
  // Its track; else (renumbered, or moved by someone) the nearest object of its label within 15 cm
  // of where it was planned, or anything within 3 cm; never one of the move's bystanders (two cans
  // side by side: when the hand has lifted one out of view, the other one is not it).
  return find_seen(target_track_, target_centre_, target_label_, 0.15, 0.03, true);
}

bool TableTaskRunner::is_target(const SeenObject& o, const SeenObject* t) const {
  // The target (current_target(), found once per use) or a piece of it (the tracker's fragments
  // near it): never an obstacle.
  return &o == t || o.track == target_track_ || (o.centre - target_centre_).norm() < 0.03 ||
         (t != nullptr && (o.centre - t->centre).norm() < 0.03) ||
         (placing() && (o.centre.head<2>() - target_place_).norm() < PLACED_NEAR_M);
}

bool TableTaskRunner::placing() const noexcept {
  // From the place on the target stands at its spot (under a new track: the hand hid it).
  const Phase p = manager_.phase();
  return state_ == State::RUNNING &&
         (p == Phase::PLACE || p == Phase::RELEASE || p == Phase::RETREAT);
}

bool TableTaskRunner::arm_hides(const Vector3d& base_point, double radius_m) const noexcept {
  return occludes(std::span(sight_).first(sight_count_), Vector3d::Zero(),
                  camera_from_base_ * base_point, radius_m);
}

bool TableTaskRunner::spots_swap(std::size_t a, std::size_t b) const {
  if (!packed_) return true;  // the grid's spots (or the user's places): room for any object
  const Vector2d at_a = moves_[a].to, at_b = moves_[b].to;
  std::vector<Footprint> others = occupied_;
  for (std::size_t k = 0; k < moves_.size(); ++k)  // every other place given (a retry repeats one)
    if (moves_[k].to != at_a && moves_[k].to != at_b) others.push_back({moves_[k].to, radii_[k]});
  const Footprint a_at_b{at_b, radii_[a]}, b_at_a{at_a, radii_[b]};
  others.push_back(b_at_a);
  if (!fits_in_area(options_.area, a_at_b, others, packed_gap_m_)) return false;
  others.back() = a_at_b;
  return fits_in_area(options_.area, b_at_a, others, packed_gap_m_);
}

std::size_t TableTaskRunner::add_spheres(const SeenObject& o, std::size_t used) {
  if (used + MAX_BOX_SPHERES > others_.size()) return used;
  return used + cover_box(o.box, std::span(others_).subspan(used, MAX_BOX_SPHERES));
}

}  // namespace orthoflow::manipulation
