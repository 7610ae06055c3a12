#include "graphs/nodes/tracker.hpp"

#include <algorithm>
#include <cmath>

namespace orthoflow::graphs {

namespace {

constexpr std::size_t MAX_INPUTS = 256;  // clusters per frame the share matrix has room for

// Share of the points inside [lo - m, hi + m] shifted by `shift`: every point tested.
float share_inside_scan(kernels::PointsView p, const std::array<float, 3>& lo,
                        const std::array<float, 3>& hi, const std::array<float, 3>& shift,
                        float m) noexcept {
  if (p.empty()) return 0.0F;
  std::size_t inside = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const float x = p.x[i] - shift[0], y = p.y[i] - shift[1], z = p.z[i] - shift[2];
    inside += static_cast<std::size_t>(x >= lo[0] - m && x <= hi[0] + m && y >= lo[1] - m &&
                                       y <= hi[1] + m && z >= lo[2] - m && z <= hi[2] + m);
  }
  return static_cast<float>(inside) / static_cast<float>(p.size());
}

}  // namespace

float share_inside(kernels::PointsView p, const std::array<float, 3>& lo,
                   const std::array<float, 3>& hi, const std::array<float, 3>& shift, float m,
                   const std::array<float, 3>& p_lo, const std::array<float, 3>& p_hi,
                   bool bounds_known) noexcept {
  if (p.empty()) return 0.0F;
  if (bounds_known) {
    // Rounding is monotonic, so (max x) - shift is the largest of the points' x - shift: a box
    // outside on one axis holds no point, a box that holds the bounds holds every point. Exact.
    bool all = true;
    for (std::size_t a = 0; a < 3; ++a) {
      const float b0 = p_lo[a] - shift[a], b1 = p_hi[a] - shift[a];
      if (b1 < lo[a] - m || b0 > hi[a] + m) return 0.0F;
      all = all && b0 >= lo[a] - m && b1 <= hi[a] + m;
    }
    if (all) return 1.0F;
  }
  return share_inside_scan(p, lo, hi, shift, m);
}

float share_inside_reference(kernels::PointsView p, const std::array<float, 3>& lo,
                             const std::array<float, 3>& hi, const std::array<float, 3>& shift,
                             float m) noexcept {
  return share_inside_scan(p, lo, hi, shift, m);
}

Tracker::Tracker(const TrackerParams& params) : params_(params) {
  tracks_.reserve(params.max_tracks);
  share_.resize(MAX_INPUTS * params.max_tracks);
  bounds_.resize(MAX_INPUTS);
  pair_.resize(MAX_INPUTS);
  taken_.resize(params.max_tracks);
}

void Tracker::match(std::int64_t stamp_ns, std::span<const TrackInput> inputs) noexcept {
  const std::size_t nt = tracks_.size();
  for (std::size_t i = 0; i < inputs.size(); ++i) {  // one pass over the points, not one per track
    const kernels::PointsView p = inputs[i].points;
    PointBounds& b = bounds_[i];
    b.finite = true;
    b.lo = {p.empty() ? 0.0F : p.x[0], p.empty() ? 0.0F : p.y[0], p.empty() ? 0.0F : p.z[0]};
    b.hi = b.lo;
    for (std::size_t k = 0; k < p.size(); ++k) {
      const float c[3] = {p.x[k], p.y[k], p.z[k]};
      for (std::size_t a = 0; a < 3; ++a) {
        b.finite = b.finite && std::isfinite(c[a]);
        b.lo[a] = std::min(b.lo[a], c[a]);
        b.hi[a] = std::max(b.hi[a], c[a]);
      }
    }
  }
  for (std::size_t t = 0; t < nt; ++t) {
    const Track& tr = tracks_[t];
    const auto dt = static_cast<float>(static_cast<double>(stamp_ns - tr.last_seen_ns) * 1e-9);
    const std::array<float, 3> shift{tr.velocity[0] * dt, tr.velocity[1] * dt, tr.velocity[2] * dt};
    for (std::size_t i = 0; i < inputs.size(); ++i) {
      share_[i * nt + t] =
          share_inside(inputs[i].points, tr.box_min, tr.box_max, shift, params_.box_margin,
                       bounds_[i].lo, bounds_[i].hi, bounds_[i].finite);
    }
  }
  std::fill(pair_.begin(), pair_.begin() + static_cast<std::ptrdiff_t>(inputs.size()), -1);
  std::fill(taken_.begin(), taken_.end(), std::uint8_t{0});
  // Greedy by share: at most min(inputs, tracks) rounds, each a scan of the matrix (ties: lowest
  // index).
  for (std::size_t round = 0; round < std::min(inputs.size(), nt); ++round) {
    float best = params_.min_share;
    std::size_t bi = 0, bt = 0;
    bool found = false;
    for (std::size_t i = 0; i < inputs.size(); ++i) {
      if (pair_[i] >= 0) continue;
      for (std::size_t t = 0; t < nt; ++t) {
        if (taken_[t] == 0 && share_[i * nt + t] >= best && (!found || share_[i * nt + t] > best)) {
          best = share_[i * nt + t];
          bi = i;
          bt = t;
          found = true;
        }
      }
    }
    if (!found) break;
    pair_[bi] = static_cast<std::int32_t>(bt);
    taken_[bt] = 1;
  }
}

void Tracker::continue_track(Track& t, const TrackInput& in, std::int64_t stamp_ns,
                             TrackOutput& out) noexcept {
  const double dt = static_cast<double>(stamp_ns - t.last_seen_ns) * 1e-9;
  float speed = 0.0F;
  if (dt > 0.0) {
    for (std::size_t a = 0; a < 3; ++a) {
      const auto v = static_cast<float>((in.centroid[a] - t.centroid[a]) / dt);
      t.velocity[a] =
          0.5F * t.velocity[a] + 0.5F * v;  // smoothed: segmentation jitters by millimetres
    }
    speed = std::sqrt(t.velocity[0] * t.velocity[0] + t.velocity[1] * t.velocity[1] +
                      t.velocity[2] * t.velocity[2]);
  }
  out.key_view = false;
  if (speed > params_.moving_speed) {
    t.moving = true;
    t.slow_frames = 0;
  } else if (t.moving && ++t.slow_frames >= params_.static_frames) {
    t.moving = false;  // static again after moving: a new key view (thesis Table 3.1)
    out.key_view = true;
  }
  t.centroid = in.centroid;
  t.box_min = in.box_min;
  t.box_max = in.box_max;
  t.last_seen_ns = stamp_ns;
  out.track_id = t.id;
  out.new_track = false;
  out.moving = t.moving;
}

void Tracker::start_track(const TrackInput& in, std::int64_t stamp_ns, TrackOutput& out) noexcept {
  out = TrackOutput{};
  if (tracks_.size() == params_.max_tracks) return;  // untracked: id 0
  Track t;
  t.id = next_id_++;
  t.centroid = in.centroid;
  t.box_min = in.box_min;
  t.box_max = in.box_max;
  t.last_seen_ns = stamp_ns;
  tracks_.push_back(t);  // within the reserved capacity: no allocation
  out.track_id = t.id;
  out.new_track = true;
  out.key_view = true;
}

// nt: the tracks in the share matrix (those that existed before this frame's new tracks).
bool Tracker::attach_fragment(std::size_t input, std::size_t nt, const TrackInput& in,
                              TrackOutput& out) noexcept {
  std::size_t best = nt;
  for (std::size_t t = 0; t < nt; ++t) {
    if (taken_[t] != 0 && share_[input * nt + t] >= params_.fragment_share &&
        (best == nt || share_[input * nt + t] > share_[input * nt + best])) {
      best = t;
    }
  }
  if (best == nt) return false;
  Track& t = tracks_[best];
  for (std::size_t a = 0; a < 3; ++a) {
    t.box_min[a] = std::min(t.box_min[a], in.box_min[a]);
    t.box_max[a] = std::max(t.box_max[a], in.box_max[a]);
  }
  out = TrackOutput{t.id, false, t.moving, false, true};
  return true;
}

void Tracker::update(std::int64_t stamp_ns, std::span<const TrackInput> inputs,
                     std::span<TrackOutput> outputs) noexcept {
  inputs = inputs.first(std::min(inputs.size(), MAX_INPUTS));
  match(stamp_ns, inputs);
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    if (pair_[i] >= 0)
      continue_track(tracks_[static_cast<std::size_t>(pair_[i])], inputs[i], stamp_ns, outputs[i]);
  }
  const std::size_t continued = tracks_.size();  // new tracks below are not in the share matrix
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    if (pair_[i] < 0 && !(continued > 0 && attach_fragment(i, continued, inputs[i], outputs[i]))) {
      start_track(inputs[i], stamp_ns, outputs[i]);
    }
  }
  // End the tracks not seen for lost_timeout_s (the new ones were just seen).
  const auto timeout = static_cast<std::int64_t>(params_.lost_timeout_s * 1e9);
  std::erase_if(tracks_, [&](const Track& t) { return stamp_ns - t.last_seen_ns > timeout; });
}

}  // namespace orthoflow::graphs
