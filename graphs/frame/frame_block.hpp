#pragma once
/// @file
/// @brief FrameBlock: how one pool block carries a frame through the tabletop graph. The raw frame
/// (engine/frame_payload.hpp layout) sits at offset 0, so a source fills it in place; every stage
/// then writes its results into its own region of the same block (nothing is copied between
/// stages and nothing is allocated). Regions, each 64-byte aligned:
///   raw frame | FrameState (counts, plane, objects, truth) | voxel centroids | hull | object
///   points | descriptors.
/// Capacity (points per frame) follows from the pool's block size and the descriptor room the graph
/// needs per object: capacity_for(block_bytes, room). The descriptors region is the rest of the
/// block, split evenly among MAX_OBJECTS objects in whole DESCRIPTOR_ALIGN steps, so a block
/// sized for a larger room (a set of spin images) gives every object that room.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "core/fixed_text.hpp"
#include "core/result.hpp"
#include "engine/frame_payload.hpp"
#include "kernels/cluster_stats.hpp"
#include "kernels/plane_distance.hpp"
#include "kernels/table_verdict.hpp"
#include "kernels/tabletop_stages.hpp"

namespace orthoflow::graphs {

inline constexpr std::size_t MAX_OBJECTS = 64;    ///< candidate objects kept per frame
inline constexpr std::size_t MAX_HULL = 2048;     ///< support-polygon vertices kept
inline constexpr std::size_t MAX_GOOD_BINS = 20;  ///< descriptor room: 3 * 20^2 floats per object
/// The least descriptor room per object: GOOD's largest, and every histogram (bag of words,
/// topics).
inline constexpr std::size_t MAX_DESCRIPTOR = 3 * MAX_GOOD_BINS * MAX_GOOD_BINS;
inline constexpr std::size_t DESCRIPTOR_ALIGN = 16;  ///< rooms are whole steps of 16 floats
/// @brief The room (floats per object) for descriptors of @p length values: at least
/// MAX_DESCRIPTOR, rounded up to DESCRIPTOR_ALIGN.
[[nodiscard]] constexpr std::size_t descriptor_room_for(std::size_t length) noexcept {
  const std::size_t n = length < MAX_DESCRIPTOR ? MAX_DESCRIPTOR : length;
  return (n + DESCRIPTOR_ALIGN - 1) / DESCRIPTOR_ALIGN * DESCRIPTOR_ALIGN;
}
inline constexpr std::size_t MAX_TRUTH = 64;  ///< ground-truth objects a source can describe

/// @brief Fixed-capacity text (labels, categories, node names): copying never allocates.
using Text = core::Text;

/// @brief One ground-truth object of a synthetic or annotated frame (label value -> category).
struct TruthObject {
  std::uint32_t label = 0;  ///< per-pixel label value of its points
  Text category;            ///< empty if the source does not know it
};

/// @brief Everything the graph learns about one candidate object of a frame.
struct ObjectRecord {
  std::uint32_t first = 0;  ///< its points: object_points()[first, first + count)
  std::uint32_t count = 0;
  kernels::ClusterStats stats{};
  std::uint32_t track_id = 0;  ///< 0 until the tracker assigns one
  bool new_track = false;      ///< the track started with this view
  bool moving = false;
  bool key_view = false;  ///< thesis Table 3.1: tracking started, or static again after moving
  bool fragment = false;  ///< a piece of an object whose main cluster has the same track id
  std::uint32_t truth_label = 0;  ///< majority ground-truth label of its points (0 = none)
  Text truth_category;            ///< category of that ground-truth object, if known
  // describe
  bool described = false;
  std::uint32_t good_flags = 0;
  std::uint32_t descriptor_length = 0;
  std::array<float, 16> frame{};  ///< world -> object, row-major (kernels::GoodResult::frame)
  std::array<float, 3> bbox{};
  // recognise
  bool recognised = false;  ///< the learner was asked about this view in this frame
  /// Not asked in this frame (the recognise node's period had not run out for its track): label,
  /// unknown, score, nearest and runner_up are the track's answer from its last ask.
  bool carried = false;
  bool unknown = true;
  Text label;  ///< this frame's answer (smoothed over the track)
  float score = 0.0F;
  Text nearest;  ///< the best category even when the answer is Unknown
  Text runner_up;
  float runner_up_score = 0.0F;  ///< the runner-up's decision value (same scale as score)
  bool taught = false;           ///< this view was taught in this frame
  Text taught_as;                ///< ... under this label
};

/// @brief Why a frame produced nothing (or less than it should). Plain data: set on the frame path
/// without allocating. One rule: the first error a frame meets is the one it reports (set() keeps
/// it; later stages see a frame that already failed and do not overwrite it).
struct FrameError {
  static constexpr std::size_t DETAIL_MAX_BYTES = 511;
  enum class Code : std::uint8_t {
    NONE,
    FRAME_TOO_LARGE,  ///< source: more points than the pool block holds (value: the point count)
    FILE_UNREADABLE,  ///< pcd_source: the file did not parse (cause: formats::IoError::Code;
                      ///< detail: message)
    INVALID_FRAME,    ///< the block holds no valid frame (cause: engine::FrameError)
    SEGMENTATION,     ///< a segmentation stage failed: segmentation holds the stage's typed reason
  };
  Code code = Code::NONE;
  std::uint8_t cause = 0;
  double value = 0.0;
  kernels::SegmentationError segmentation{};
  Text stage;  ///< the node that reported it
  /// FILE_UNREADABLE: the reader's message, its middle elided past DETAIL_MAX_BYTES (the file's
  /// path and the reason stay whatever the folder's depth).
  core::FixedText<DETAIL_MAX_BYTES> detail;
  [[nodiscard]] bool empty() const noexcept { return code == Code::NONE; }
  /// @brief The code's name, e.g. "SEGMENTATION". Never allocates.
  [[nodiscard]] static std::string_view name(Code code) noexcept;
  /// @brief Records an error unless the frame already has one. @return true if recorded.
  bool set(Code c, std::string_view node, std::uint8_t why = 0, double number = 0.0) noexcept;
  /// @brief Records a segmentation stage's error (same first-error rule).
  bool set(std::string_view node, const kernels::SegmentationError& e) noexcept;
  /// @brief "node: CODE: reason". Allocates: off the frame path.
  [[nodiscard]] std::string to_string() const;
};

/// @brief Where a frame's "up" came from: its sensor (the Kinect's accelerometer, a simulated
/// camera's pose), the table node's configured camera pose, or nowhere.
enum class Gravity : std::uint8_t { NONE, SENSOR, CONFIGURED };
/// @brief "none", "sensor", "configured".
[[nodiscard]] std::string_view gravity_name(Gravity g) noexcept;

/// @brief Per-frame results of every stage; lives in the block after the raw frame.
struct FrameState {
  std::uint32_t truth_count = 0;
  std::array<TruthObject, MAX_TRUTH> truth{};
  std::uint32_t kept = 0;  ///< finite points inside the ROI that fed the plane input
  std::uint32_t voxels =
      0;  ///< plane input: dense sample (organized) or voxel centroids, at voxels()[0, voxels)
  std::uint32_t sparse =
      0;  ///< plane input: RANSAC's scoring sample, at voxels()[voxels, voxels + sparse)
  bool organized_path =
      false;               ///< preprocess took the organized path (kernels::takes_organized_path)
  kernels::AxisBox roi{};  ///< the region of interest preprocess applied (the prism applies it too)
  bool table_found = false;
  kernels::Plane plane{};
  std::uint32_t plane_inliers = 0;
  kernels::PlaneCheck plane_check{};  ///< how sure the table stage is of the plane
  /// The table verdict (kernels/table_verdict.hpp): table_found is true for ACCEPTED and HELD
  /// only; `judged` is what the verdict measured on this frame's own plane (when it had one).
  kernels::TableReason table_reason = kernels::TableReason::NO_PLANE;
  kernels::TableJudgement judged{};
  Gravity gravity = Gravity::NONE;  ///< where this frame's "up" came from
  std::array<float, 3> up{};        ///< unit "up" in the sensor frame (gravity != NONE)
  std::uint32_t up_age_ms = 0;      ///< age of the sensor reading behind it (Gravity::SENSOR)
  std::uint32_t up_stale_ms = 0;    ///< age of a sensor reading refused as too old (0: none)
  std::uint32_t hull_count = 0;
  std::uint32_t clusters = 0;           ///< clusters before the candidate constraints
  std::uint32_t rejected_size = 0;      ///< failed C_size
  std::uint32_t rejected_edge = 0;      ///< failed C_edge
  std::uint32_t rejected_capacity = 0;  ///< passed both but found the MAX_OBJECTS records full
  std::uint32_t object_count = 0;       ///< candidates kept in objects
  /// What the objects stage's budget (kernels::ObjectBudget) spared on this frame: the prism's
  /// pixels before thinning, the stride it clustered at (1: every pixel), whether the crowded
  /// refinements ran; the farthest candidates it dropped are rejected_capacity.
  std::uint32_t prism_points = 0;
  std::uint8_t stride = 1;
  bool refined = true;
  std::array<ObjectRecord, MAX_OBJECTS> objects{};
  FrameError error;  ///< why a stage produced nothing for this frame (empty = fine)
};

/// @brief Typed view of one pool block. Cheap to make (pointer arithmetic only).
class FrameBlock {
 public:
  /// @brief Block bytes needed for frames of up to @p capacity points with @p room descriptor
  /// floats per object (@pre a multiple of DESCRIPTOR_ALIGN: descriptor_room_for()).
  [[nodiscard]] static std::size_t bytes_for(std::size_t capacity,
                                             std::size_t room = MAX_DESCRIPTOR) noexcept;
  /// @brief Largest capacity a block of @p block_bytes holds with @p room descriptor floats per
  /// object (0 if not even one point).
  [[nodiscard]] static std::size_t capacity_for(std::size_t block_bytes,
                                                std::size_t room = MAX_DESCRIPTOR) noexcept;
  /// @brief Descriptor floats per object a block of @p block_bytes holding @p capacity points
  /// leaves after the other regions (a multiple of DESCRIPTOR_ALIGN).
  [[nodiscard]] static std::size_t room_in(std::size_t block_bytes, std::size_t capacity) noexcept;
  /// @brief Views @p block. @pre block.size() >= bytes_for(capacity), 64-byte aligned (pool blocks
  /// are). Every object's descriptor room is what the block holds after the other regions.
  FrameBlock(std::span<std::byte> block, std::size_t capacity) noexcept;

  /// @brief Where a source writes the raw frame (engine::write_frame / layout_frame).
  [[nodiscard]] std::span<std::byte> raw() const noexcept { return raw_; }
  /// @brief The validated raw frame (also resolves a frame held in an IPC chunk).
  [[nodiscard]] Result<engine::FrameView, engine::FrameError> frame() const noexcept;
  /// @brief True if the raw region holds an engine::FrameRef to a frame elsewhere (ipc_subscribe).
  [[nodiscard]] bool external() const noexcept;
  [[nodiscard]] FrameState& state() const noexcept { return *state_; }
  [[nodiscard]] kernels::PointsSpan voxels() const noexcept { return voxels_; }
  [[nodiscard]] std::span<double> hull_u() const noexcept { return hull_u_; }
  [[nodiscard]] std::span<double> hull_v() const noexcept { return hull_v_; }
  [[nodiscard]] kernels::PointsSpan object_points() const noexcept { return object_points_; }
  /// @brief Points of object @p i (after the objects stage).
  [[nodiscard]] kernels::PointsView object_view(std::size_t i) const noexcept;
  /// @brief Descriptor room of object @p i (descriptor_room() floats).
  [[nodiscard]] std::span<float> descriptor(std::size_t i) const noexcept;
  [[nodiscard]] std::size_t capacity() const noexcept { return capacity_; }
  /// @brief Descriptor floats per object (a multiple of DESCRIPTOR_ALIGN; MAX_DESCRIPTOR for a
  /// block of exactly bytes_for(capacity)).
  [[nodiscard]] std::size_t descriptor_room() const noexcept { return room_; }

 private:
  std::span<std::byte> raw_;
  FrameState* state_ = nullptr;
  kernels::PointsSpan voxels_;
  std::span<double> hull_u_, hull_v_;
  kernels::PointsSpan object_points_;
  std::span<float> descriptors_;
  std::size_t capacity_ = 0;
  std::size_t room_ = 0;
};

}  // namespace orthoflow::graphs
