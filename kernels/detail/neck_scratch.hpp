#pragma once
/// @file
/// @brief The neck split's grid kernel (kernels/neck_split.cpp): a footprint drawn on a grid of
/// cells is cut into its round cores, each core's share ending at the neck that joins it to the
/// next (a watershed on the distance to the footprint's edge, keeping only cores that are wide
/// and whose neck is narrow). Scalar, integer arithmetic only: the same cut on every machine.
#include <cstddef>
#include <cstdint>
#include <vector>

namespace orthoflow::kernels::detail {

/// @brief Cells per side of the largest footprint cut (64 cm at 5 mm cells; larger pieces stay).
inline constexpr std::size_t NECK_GRID = 128;
/// @brief Distance units per cell along a row or column (the 3-4 chamfer: 4 along a diagonal).
inline constexpr std::uint32_t NECK_UNIT = 3;

/// @brief What counts as a core and as a neck, in distance units (NECK_UNIT per cell).
struct NeckRule {
  std::uint32_t min_core = 9;  ///< a core's peak distance to the footprint's edge, at least
  float ratio = 0.5F;          ///< a neck's distance at most ratio x the smaller core's peak
  float max_round = 1.5F;      ///< each part's area at most this x the disc of its core's peak
};

/// @brief Grids and lists for one footprint at a time (sized once: nothing allocates after).
struct NeckScratch {
  explicit NeckScratch(std::size_t max_points = 0);
  std::vector<std::uint8_t> cells;   ///< in: 1 where a point fell; the filled footprint after
  std::vector<std::uint8_t> spare;   ///< closing, hole fill
  std::vector<std::uint16_t> dist;   ///< chamfer distance to the nearest cell outside
  std::vector<std::uint32_t> order;  ///< footprint cells, farthest from the edge first
  std::vector<std::uint32_t> count;  ///< counting sort by distance
  std::vector<std::int32_t> parent;  ///< union-find over the cells (-1: not reached yet)
  std::vector<std::uint16_t> peak;   ///< per root: its component's highest distance
  std::vector<std::uint32_t> birth;  ///< per root: where its component was born
  std::vector<std::uint8_t> marked;  ///< per cell: a core was born here
  std::vector<std::int8_t> part;     ///< out: per cell its part (-1 outside or unassigned)
  // The split's per-point lists (kernels/neck_split.cpp).
  std::vector<float> u, v;                ///< each prism pixel on the table plane
  std::vector<std::uint32_t> by_cluster;  ///< prism pixels grouped by cluster
  std::vector<std::uint32_t> start;       ///< per cluster: its first entry in by_cluster
};

/// @brief Cuts the footprint in s.cells (@p w x @p h cells, row-major; the outermost ring of cells
/// must be empty) at its necks: closes one-cell gaps, fills enclosed holes, takes the chamfer
/// distance to the edge, and floods from the cores of @p rule down to the necks. Writes s.part (0
/// = the core farthest from the edge, then in falling peak order).
/// @return the number of cores (0 or 1: nothing to cut). Deterministic; allocation-free.
/// @pre w, h <= NECK_GRID.
std::size_t neck_parts(std::size_t w, std::size_t h, const NeckRule& rule, NeckScratch& s) noexcept;

}  // namespace orthoflow::kernels::detail
