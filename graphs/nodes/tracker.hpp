#pragma once
/// @file
/// @brief Tracker: keeps object identities across frames (specs/PIPELINE.md section 5, thesis 3.3).
/// A cluster continues the track whose predicted bounding box holds the largest share of its points
/// (at least min_share); pairs are taken greedily by share. Unmatched clusters start tracks with
/// new ids; tracks unseen for lost_timeout_s end. A constant-velocity model moves each box to the
/// frame's time before matching. Key views (thesis Table 3.1): the first view of a track, and the
/// first view after a moving object has been static for static_frames frames.
///
/// Limits against the thesis's particle filter (docs/TABLETOP.md, "Tracking, and its limits"): no
/// colour or shape likelihood, so two touching objects that merge into one cluster continue only
/// one track, and a fast object (more than its own size per frame, beyond what the velocity
/// predicts) starts a new track.
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "kernels/point_cloud.hpp"

namespace orthoflow::graphs {

/// @brief Tracker settings (start-up).
struct TrackerParams {
  float min_share = 0.3F;  ///< share of a cluster's points inside a track's box to continue it
  float fragment_share =
      0.6F;  ///< an extra cluster this much inside a continued track's box is a piece of it
  float box_margin = 0.02F;  ///< metres added around a track's box before counting (sensor noise)
  double lost_timeout_s = 1.0;  ///< a track unseen this long ends
  float moving_speed = 0.03F;   ///< m/s of centroid motion above which an object counts as moving
  std::uint32_t static_frames = 5;  ///< slow frames in a row before a moving object is static again
  std::size_t max_tracks = 64;
};

/// @brief Share of the points @p p inside the box [lo - m, hi + m] moved by @p shift. With @p
/// bounds_known, [p_lo, p_hi] is the points' exact bounding box: a box that misses it on one axis
/// gives 0 and one that holds it gives 1 without a scan, otherwise every point is tested; the
/// result equals share_inside_reference() bit for bit. Allocation-free.
[[nodiscard]] float share_inside(kernels::PointsView p, const std::array<float, 3>& lo,
                                 const std::array<float, 3>& hi, const std::array<float, 3>& shift,
                                 float m, const std::array<float, 3>& p_lo,
                                 const std::array<float, 3>& p_hi, bool bounds_known) noexcept;
/// @brief The scalar reference twin of share_inside(): every point tested.
[[nodiscard]] float share_inside_reference(kernels::PointsView p, const std::array<float, 3>& lo,
                                           const std::array<float, 3>& hi,
                                           const std::array<float, 3>& shift, float m) noexcept;

/// @brief One cluster of the current frame, as the tracker sees it.
struct TrackInput {
  kernels::PointsView points;
  std::array<float, 3> centroid{};
  std::array<float, 3> box_min{};
  std::array<float, 3> box_max{};
};

/// @brief What the tracker decided for one cluster.
struct TrackOutput {
  std::uint32_t track_id = 0;
  bool new_track = false;
  bool moving = false;
  bool key_view = false;
  bool fragment =
      false;  ///< a piece of an object another cluster of this frame continues (same id)
};

/// @brief Track state. @note Not thread-safe; allocation-free after construction; deterministic.
class Tracker {
 public:
  explicit Tracker(const TrackerParams& params);
  /// @brief Associates @p inputs (one frame, stamped @p stamp_ns) with tracks; writes @p outputs.
  /// @pre outputs.size() >= inputs.size(); stamps do not decrease. Inputs beyond max_tracks that
  /// need a new track get track_id 0 (untracked).
  void update(std::int64_t stamp_ns, std::span<const TrackInput> inputs,
              std::span<TrackOutput> outputs) noexcept;
  /// @brief Tracks alive now.
  [[nodiscard]] std::size_t active() const noexcept { return tracks_.size(); }
  /// @brief Tracks ever started (the last id handed out).
  [[nodiscard]] std::uint32_t started() const noexcept { return next_id_ - 1; }

 private:
  /// The exact bounding box of an input's points (finite: every coordinate of every point was).
  struct PointBounds {
    std::array<float, 3> lo{}, hi{};
    bool finite = false;
  };
  struct Track {
    std::uint32_t id = 0;
    std::array<float, 3> centroid{}, velocity{}, box_min{}, box_max{};
    std::int64_t last_seen_ns = 0;
    bool moving = false;
    std::uint32_t slow_frames = 0;
  };
  void match(std::int64_t stamp_ns, std::span<const TrackInput> inputs) noexcept;
  void continue_track(Track& t, const TrackInput& in, std::int64_t stamp_ns,
                      TrackOutput& out) noexcept;
  void start_track(const TrackInput& in, std::int64_t stamp_ns, TrackOutput& out) noexcept;
  bool attach_fragment(std::size_t input, std::size_t nt, const TrackInput& in,
                       TrackOutput& out) noexcept;

  TrackerParams params_;
  std::vector<Track> tracks_;        // capacity max_tracks, reserved once
  std::vector<float> share_;         // inputs x tracks, reserved once
  std::vector<std::int32_t> pair_;   // input -> track index or -1
  std::vector<std::uint8_t> taken_;  // track already paired
  std::vector<PointBounds> bounds_;  // per input: its points' exact bounding box
  std::uint32_t next_id_ = 1;
};

}  // namespace orthoflow::graphs
