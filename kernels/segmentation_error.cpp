// SegmentationError (kernels/tabletop_stages.hpp): the names of its codes and its full message.
#include <cstdio>
#include <string>

#include "kernels/tabletop_stages.hpp"

namespace orthoflow::kernels {

namespace {

/// "x [-1, 1] y [-1, 1] z [0.3, 2] m": the box as a user wrote it (%g: no trailing zeros).
std::string box_text(const AxisBox& box) {
  char text[160];
  std::snprintf(text, sizeof text, "x [%g, %g] y [%g, %g] z [%g, %g] m",
                static_cast<double>(box.min[0]), static_cast<double>(box.max[0]),
                static_cast<double>(box.min[1]), static_cast<double>(box.max[1]),
                static_cast<double>(box.min[2]), static_cast<double>(box.max[2]));
  return text;
}

}  // namespace

std::string_view to_string(SegmentationError::Code code) noexcept {
  using C = SegmentationError::Code;
  switch (code) {
    case C::CLOUD_TOO_LARGE:
      return "CLOUD_TOO_LARGE";
    case C::NOT_WIDTH_X_HEIGHT:
      return "NOT_WIDTH_X_HEIGHT";
    case C::OUTPUT_TOO_SMALL:
      return "OUTPUT_TOO_SMALL";
    case C::VOXEL_GRID_FAILED:
      return "VOXEL_GRID_FAILED";
    case C::NO_PLANE:
      return "NO_PLANE";
    case C::FEW_SAMPLE_INLIERS:
      return "FEW_SAMPLE_INLIERS";
    case C::DEGENERATE_HULL:
      return "DEGENERATE_HULL";
    case C::HULL_TOO_LARGE:
      return "HULL_TOO_LARGE";
    case C::CLUSTERING_FAILED:
      return "CLUSTERING_FAILED";
    case C::FEW_POINTS_IN_ROI:
      return "FEW_POINTS_IN_ROI";
  }
  return "UNKNOWN";
}

std::string SegmentationError::to_string() const {
  using C = Code;
  const std::string name(kernels::to_string(code));
  const std::string count = std::to_string(static_cast<std::uint64_t>(value));
  switch (code) {
    case C::CLOUD_TOO_LARGE:
      return "segmentation: " + name + ": " + count + " points, more than it was sized for";
    case C::NOT_WIDTH_X_HEIGHT:
      return "segmentation: " + name + ": organized cloud of " + count + " points is not " +
             std::to_string(width) + " x " + std::to_string(height);
    case C::OUTPUT_TOO_SMALL:
      return "segmentation: " + name + ": the plane input needs room for " + count + " points";
    case C::VOXEL_GRID_FAILED:
      return "segmentation: " + name + ": " +
             VoxelGridError{VoxelGridError::Code{cause}, value}.to_string();
    case C::NO_PLANE:
      return "segmentation: " + name + ": " +
             RansacError{RansacError::Code{cause}, value}.to_string();
    case C::FEW_SAMPLE_INLIERS:
      return "segmentation: " + name + ": the plane has fewer than 3 inliers on the sample";
    case C::DEGENERATE_HULL:
      return "segmentation: " + name + ": the plane inliers have a degenerate hull";
    case C::HULL_TOO_LARGE:
      return "segmentation: " + name + ": " + count + " hull vertices";
    case C::CLUSTERING_FAILED:
      return "segmentation: " + name + ": " +
             ClusterError{ClusterError::Code{cause}, value}.to_string();
    case C::FEW_POINTS_IN_ROI:
      return "segmentation: " + name + ": " + std::to_string(finite) + " finite points, " + count +
             " inside the region of interest " + box_text(roi) + "; a plane needs at least 3";
  }
  return "segmentation: " + name;
}

}  // namespace orthoflow::kernels
