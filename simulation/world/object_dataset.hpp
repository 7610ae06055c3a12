#pragma once
/// @file
/// @brief The object-view dataset: single segmented partial views of synthetic objects, as the
/// Kinect model sees them, written as `DIR/<category>/<category>_<ii>/view_<vvv>.pcd`.
///
/// Each view renders one object standing on a large table (no floor) with the full sensor model of
/// synthetic_scene.hpp, then keeps only the object's pixels (x, y, z in the sensor frame, rgb; an
/// unorganized cloud). The camera elevation above the table is the table tilt (20-70 degrees), the
/// azimuth is the object's yaw (all around), the distance is the depth of the table point under the
/// object (0.6-1.5 m). Determinism: view v of instance i of category c depends only on (seed, c, i,
/// v).
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "core/result.hpp"
#include "kernels/point_cloud.hpp"
#include "simulation/world/object_catalog.hpp"
#include "simulation/world/synthetic_scene.hpp"

namespace orthoflow::simulation {

/// @brief Where the camera sees an object from.
struct ViewSpec {
  double elevation_rad = 0.785;  ///< angle between the optical axis and the table plane
  double azimuth_rad = 0.0;      ///< the object's yaw about the table normal
  double distance_m = 1.0;       ///< depth of the object's base point on the optical axis
};

/// @brief What to generate (plain struct, validated by write_object_dataset).
struct DatasetConfig {
  std::vector<Category> categories{};  ///< empty: all CATEGORY_COUNT categories
  std::uint32_t instances = 3;         ///< per category, at most 1000
  std::uint32_t views = 10;            ///< per instance, at most 10000
  std::uint64_t seed = 1;              ///< picks the instances' shapes, the views and the noise
  double min_elevation_deg = 20.0, max_elevation_deg = 70.0;
  double min_distance_m = 0.6, max_distance_m = 1.5;
  RenderOptions render{};  ///< sensor model (e.g. a smaller image for quick tests)
};

/// @brief Why a dataset could not be written.
struct DatasetError {
  enum class Code : std::uint8_t {
    BAD_CONFIG,    ///< a count or range is out of bounds
    EMPTY_VIEW,    ///< an object stayed invisible from every viewpoint tried
    WRITE_FAILED,  ///< a directory or file could not be written
  };
  Code code = Code::BAD_CONFIG;
  std::string message;
  /// @brief "<code name>: <message>".
  [[nodiscard]] std::string to_string() const;
};

/// @brief What was written.
struct DatasetSummary {
  std::size_t categories = 0;
  std::size_t files = 0;
  std::size_t points = 0;
  std::size_t min_points = 0;  ///< fewest points in one view
};

/// @brief Renders the segmented view of @p model from @p view into @p out (unorganized x, y, z,
/// rgb), using @p frame as scratch. Only the image window around the object's bounding sphere is
/// ray cast (the same pixels and rays as the full image, so the points are those of a full frame;
/// the noise draws differ). @return the number of points.
/// @note Deterministic in @p rng's state; not thread-safe on shared arguments.
std::size_t render_object_view(const ObjectModel& model, const ViewSpec& view,
                               const RenderOptions& options, core::Rng& rng,
                               kernels::PointCloud& frame, kernels::PointCloud& out);

/// @brief The seeded viewpoint of view @p v of instance @p i of @p category (within the config's
/// ranges).
[[nodiscard]] ViewSpec dataset_view(const DatasetConfig& config, Category category, std::uint32_t i,
                                    std::uint32_t v, std::uint32_t attempt = 0) noexcept;

/// @brief The relative path `<category>/<category>_<ii>/view_<vvv>.pcd`.
[[nodiscard]] std::filesystem::path dataset_view_path(Category category, std::uint32_t i,
                                                      std::uint32_t v);

/// @brief Generates the whole dataset under @p dir (created if needed; existing files are
/// replaced).
[[nodiscard]] Result<DatasetSummary, DatasetError> write_object_dataset(
    const DatasetConfig& config, const std::filesystem::path& dir);

}  // namespace orthoflow::simulation
