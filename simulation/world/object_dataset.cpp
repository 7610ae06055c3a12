// The object-view dataset generator (object_dataset.hpp).
#include "simulation/world/object_dataset.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <system_error>
#include <utility>

#include "formats/pcd_io.hpp"

namespace orthoflow::simulation {
namespace {

constexpr double PI = 3.14159265358979323846;
constexpr std::uint32_t MAX_INSTANCES = 1000;
constexpr std::uint32_t MAX_VIEWS = 10000;
constexpr std::uint32_t VIEW_ATTEMPTS = 8;   // fresh viewpoints tried before a view counts as empty
constexpr std::size_t MIN_VIEW_POINTS = 20;  // fewer points than this is not a usable view
constexpr double TABLE_SIZE_M = 3.0;         // large enough to fill the view behind any object

/// SplitMix64-style mixing of the view's coordinates into one seed.
std::uint64_t mix(std::uint64_t h, std::uint64_t v) {
  h ^= v + 0x9E3779B97F4A7C15ULL + (h << 6) + (h >> 2);
  h = (h ^ (h >> 30)) * 0xBF58476D1CE4E5B9ULL;
  return h ^ (h >> 31);
}

std::uint64_t view_seed(const DatasetConfig& c, Category cat, std::uint32_t i, std::uint32_t v,
                        std::uint32_t a) {
  return mix(mix(mix(mix(c.seed, static_cast<std::uint64_t>(cat)), i), v), a);
}

Result<void, DatasetError> validate(const DatasetConfig& c) {
  std::string what;
  if (c.instances == 0 || c.instances > MAX_INSTANCES) { what = "instances must be in 1..1000"; }
  if (c.views == 0 || c.views > MAX_VIEWS) { what = "views must be in 1..10000"; }
  if (!(c.min_elevation_deg >= 5.0 && c.min_elevation_deg <= c.max_elevation_deg &&
        c.max_elevation_deg <= 90.0)) {
    what = "elevation range must satisfy 5 <= min <= max <= 90 degrees";
  }
  if (!(c.min_distance_m >= 0.5 && c.min_distance_m <= c.max_distance_m &&
        c.max_distance_m <= 3.5)) {
    what = "distance range must satisfy 0.5 <= min <= max <= 3.5 m";
  }
  for (std::size_t i = 0; i < c.categories.size() && what.empty(); ++i) {
    // Twice the same category would write its views twice over one directory and count them twice.
    if (std::find(c.categories.begin(), c.categories.begin() + static_cast<std::ptrdiff_t>(i),
                  c.categories[i]) != c.categories.begin() + static_cast<std::ptrdiff_t>(i)) {
      what = "category '" + std::string(category_name(c.categories[i])) + "' is listed twice";
    }
  }
  if (what.empty()) { return {}; }
  return err(DatasetError{DatasetError::Code::BAD_CONFIG, "dataset config: " + what});
}

/// The pixels of @p in that can see the object of @p scene, as intrinsics of that window (same
/// rays as the full image): the projection of the box [c - R, c + R] around its bounding sphere,
/// whose extreme x/z and y/z lie at corners because x/z is monotonic in x and z for z > 0.
DepthIntrinsics object_window(const Scene& scene, const DepthIntrinsics& in) {
  const ObjectModel& m = scene.objects.front().model;
  const Vec3 c = table_frame(scene.table).point(0.0, 0.0, m.height / 2);
  const double r = std::hypot(m.footprint_radius, m.height / 2) + 0.01;
  if (c[2] - r <= 0.05) { return in; }  // too close to bound cheaply: render everything
  auto span = [&](double centre, double f, double principal, std::uint32_t size) {
    double lo = 1e300, hi = -1e300;
    for (double a : {centre - r, centre + r}) {
      for (double z : {c[2] - r, c[2] + r}) {
        lo = std::min(lo, f * a / z + principal);
        hi = std::max(hi, f * a / z + principal);
      }
    }
    const double first = std::clamp(std::floor(lo), 0.0, static_cast<double>(size));
    const double last = std::clamp(std::ceil(hi) + 1.0, 0.0, static_cast<double>(size));
    return std::pair<std::uint32_t, std::uint32_t>{static_cast<std::uint32_t>(first),
                                                   static_cast<std::uint32_t>(last)};
  };
  const auto [u0, u1] = span(c[0], in.fx, in.cx, in.width);
  const auto [v0, v1] = span(c[1], in.fy, in.cy, in.height);
  return DepthIntrinsics{in.fx, in.fy, in.cx - u0, in.cy - v0, u1 - u0, v1 - v0};
}

std::size_t render_view(const DatasetConfig& config, const ObjectModel& model, std::uint32_t v,
                        kernels::PointCloud& frame, kernels::PointCloud& view) {
  std::size_t n = 0;
  for (std::uint32_t a = 0; a < VIEW_ATTEMPTS && n < MIN_VIEW_POINTS; ++a) {
    core::Rng noise(~view_seed(config, model.category, model.instance, v, a));
    const ViewSpec spec = dataset_view(config, model.category, model.instance, v, a);
    n = render_object_view(model, spec, config.render, noise, frame, view);
  }
  return n;
}

/// Renders and writes views one by one, reusing its two clouds.
struct DatasetWriter {
  const DatasetConfig& config;
  const std::filesystem::path& dir;
  DatasetSummary summary{};
  kernels::PointCloud frame{}, view{};

  Result<void, DatasetError> write_view(const ObjectModel& model, std::uint32_t v) {
    const std::filesystem::path path = dir / dataset_view_path(model.category, model.instance, v);
    const std::size_t n = render_view(config, model, v, frame, view);
    if (n < MIN_VIEW_POINTS) {
      return err(DatasetError{DatasetError::Code::EMPTY_VIEW,
                              path.string() + ": object not visible from any viewpoint"});
    }
    std::error_code ec;
    std::filesystem::create_directories(path.parent_path(), ec);
    if (ec) {
      return err(DatasetError{DatasetError::Code::WRITE_FAILED,
                              path.parent_path().string() + ": " + ec.message()});
    }
    view.info.frame_id = v;
    if (auto written = formats::write_pcd(view, path); !written) {
      return err(DatasetError{DatasetError::Code::WRITE_FAILED, written.error().to_string()});
    }
    ++summary.files;
    summary.points += n;
    summary.min_points = summary.files == 1 ? n : std::min(summary.min_points, n);
    return {};
  }
};

}  // namespace

std::string DatasetError::to_string() const {
  static constexpr const char* NAMES[] = {"bad_config", "empty_view", "write_failed"};
  return std::string(NAMES[static_cast<std::size_t>(code)]) + ": " + message;
}

std::size_t render_object_view(const ObjectModel& model, const ViewSpec& view,
                               const RenderOptions& options, core::Rng& rng,
                               kernels::PointCloud& frame, kernels::PointCloud& out) {
  Scene scene;
  scene.table = TableSpec{view.distance_m, view.elevation_rad, TABLE_SIZE_M, TABLE_SIZE_M, 0.0};
  scene.objects.push_back(PlacedObject{model, 0.0, 0.0, view.azimuth_rad});
  RenderOptions windowed = options;
  windowed.intrinsics = object_window(scene, options.intrinsics);
  if (windowed.intrinsics.width == 0 || windowed.intrinsics.height == 0) {
    frame.resize(0);
  } else {
    render_scene(scene, windowed, rng, frame);
  }
  std::size_t n = 0;
  for (std::uint32_t l : frame.label()) { n += l == OBJECT_LABEL_BASE; }
  out.remove_field(kernels::Field::LABEL);
  out.remove_field(kernels::Field::NORMALS);
  out.add_field(kernels::Field::RGB);
  out.resize_unorganized(n);
  std::size_t k = 0;
  for (std::size_t i = 0; i < frame.size(); ++i) {
    if (frame.label()[i] != OBJECT_LABEL_BASE) { continue; }
    out.x()[k] = frame.x()[i];
    out.y()[k] = frame.y()[i];
    out.z()[k] = frame.z()[i];
    out.rgb()[k] = frame.rgb()[i];
    ++k;
  }
  return n;
}

ViewSpec dataset_view(const DatasetConfig& config, Category category, std::uint32_t i,
                      std::uint32_t v, std::uint32_t attempt) noexcept {
  core::Rng r(view_seed(config, category, i, v, attempt));
  ViewSpec s;
  s.elevation_rad = r.uniform(config.min_elevation_deg, config.max_elevation_deg) * PI / 180.0;
  s.azimuth_rad = r.uniform(0.0, 2.0 * PI);
  s.distance_m = r.uniform(config.min_distance_m, config.max_distance_m);
  return s;
}

std::filesystem::path dataset_view_path(Category category, std::uint32_t i, std::uint32_t v) {
  char instance[64];
  char view[32];
  std::snprintf(instance, sizeof instance, "%s_%02u", category_name(category), i);
  std::snprintf(view, sizeof view, "view_%03u.pcd", v);
  return std::filesystem::path(category_name(category)) / instance / view;
}

Result<DatasetSummary, DatasetError> write_object_dataset(const DatasetConfig& config,
                                                          const std::filesystem::path& dir) {
  if (auto ok = validate(config); !ok) { return err(ok.error()); }
  if (dir.empty()) {  // "" would write into the working directory
    return err(DatasetError{DatasetError::Code::BAD_CONFIG,
                            "dataset config: the output directory is an empty path"});
  }
  std::vector<Category> cats = config.categories;
  if (cats.empty()) {
    for (std::size_t c = 0; c < CATEGORY_COUNT; ++c) { cats.push_back(static_cast<Category>(c)); }
  }
  DatasetWriter writer{config, dir};
  writer.summary.categories = cats.size();
  for (Category cat : cats) {
    for (std::uint32_t i = 0; i < config.instances; ++i) {
      const ObjectModel model = make_object_model(cat, i, config.seed);
      for (std::uint32_t v = 0; v < config.views; ++v) {
        if (auto ok = writer.write_view(model, v); !ok) { return err(ok.error()); }
      }
    }
  }
  return writer.summary;
}

}  // namespace orthoflow::simulation
