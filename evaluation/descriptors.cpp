#include "evaluation/descriptors.hpp"

#include <tbb/parallel_for.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>

#include "core/rng.hpp"
#include "evaluation/descriptor_cache.hpp"
#include "evaluation/progress.hpp"
#include "formats/pcd_io.hpp"
#include "kernels/voxel_grid.hpp"

namespace orthoflow::evaluation {
namespace {

/// FNV-1a: a portable 64-bit hash of names (noise seeds, cache file names).
std::uint64_t fnv1a(std::string_view s, std::uint64_t h = 0xCBF29CE484222325ULL) {
  for (const char c : s) { h = (h ^ static_cast<unsigned char>(c)) * 0x100000001B3ULL; }
  return h;
}

const char* perturbation_name(Perturbation p) {
  switch (p) {
    case Perturbation::NONE:
      return "clean";
    case Perturbation::NOISE:
      return "noise";
    case Perturbation::DOWNSAMPLE:
      return "voxel";
  }
  return "?";
}

void finite_points(const kernels::PointCloud& cloud, kernels::PointCloud& out) {
  const kernels::PointsView p = cloud.points();
  std::size_t n = 0;
  out.resize_unorganized(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (std::isfinite(p.x[i]) && std::isfinite(p.y[i]) && std::isfinite(p.z[i])) {
      out.x()[n] = p.x[i];
      out.y()[n] = p.y[i];
      out.z()[n] = p.z[i];
      ++n;
    }
  }
  out.resize_unorganized(n);
}

/// Reads, perturbs and describes one view; returns an error sentence, empty on success.
std::string describe_one(const Dataset& ds, std::size_t v, const ViewDescription& spec,
                         kernels::Describer& describer, std::span<float> out) {
  const std::filesystem::path path = ds.root / ds.views[v].relative;
  auto cloud = formats::read_pcd(path);
  if (!cloud) { return path.string() + ": " + cloud.error().to_string(); }
  kernels::PointCloud view;
  if (!perturb_view(*cloud, spec, ds.views[v].relative, view)) {
    return path.string() + ": the voxel grid refused leaf " + std::to_string(spec.amount_m) + " m";
  }
  auto described = describer.describe(view.points(), out);
  if (!described) { return path.string() + ": " + kernels::to_string(described.error()); }
  return {};
}

Result<void, EvalError> check_spec(const ViewDescription& spec) {
  if (spec.descriptor.good.bins == 0 || spec.descriptor.good.bins > kernels::GOOD_MAX_BINS) {
    return err(EvalError{EvalError::Code::BAD_CONFIG,
                         "bins must be in 1.." + std::to_string(kernels::GOOD_MAX_BINS) + ", got " +
                             std::to_string(spec.descriptor.good.bins)});
  }
  if (auto valid = spec.descriptor.validate(); !valid) {
    return err(EvalError{EvalError::Code::BAD_CONFIG, valid.error()});
  }
  if (!std::isfinite(spec.amount_m) || spec.amount_m < 0.0 ||
      (spec.perturbation == Perturbation::DOWNSAMPLE && spec.amount_m <= 0.0)) {
    return err(EvalError{EvalError::Code::BAD_CONFIG,
                         "bad perturbation amount " + std::to_string(spec.amount_m) + " m"});
  }
  return {};
}

std::filesystem::path cache_path(const Dataset& ds, const ViewDescription& spec,
                                 const std::filesystem::path& dir) {
  std::error_code ec;
  const std::filesystem::path canonical = std::filesystem::weakly_canonical(ds.root, ec);
  char hash[17];
  std::snprintf(hash, sizeof hash, "%016llx",
                static_cast<unsigned long long>(fnv1a(ec ? ds.root.string() : canonical.string())));
  return dir / (spec.key() + "-" + hash + ".ofdc");
}

DescriptorCache load_cache(const std::filesystem::path& path, std::size_t length) {
  std::ifstream f(path, std::ios::binary);
  if (!f) { return DescriptorCache{length, {}}; }
  const std::string bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  return parse_descriptor_cache(bytes, length);
}

/// Copies the cached descriptor of every view whose file is unchanged into @p table; 1 = taken from
/// the cache.
std::vector<std::uint8_t> fill_from_cache(const Dataset& ds, const DescriptorCache& cache,
                                          std::vector<FileStamp>& stamps, DescriptorTable& table) {
  std::vector<std::uint8_t> hit(ds.views.size(), 0);
  for (std::size_t v = 0; v < ds.views.size(); ++v) {
    const auto it = cache.entries.find(ds.views[v].relative);
    if (stamp_file(ds.root / ds.views[v].relative, stamps[v]) && it != cache.entries.end() &&
        it->second.stamp == stamps[v]) {
      std::copy(it->second.descriptor.begin(), it->second.descriptor.end(),
                table.values.begin() + static_cast<std::ptrdiff_t>(v * table.length));
      hit[v] = 1;
    }
  }
  return hit;
}

}  // namespace

std::string ViewDescription::key() const {
  // "good-invariant-15-none": the same key as before the specification existed, so caches stay
  // valid.
  // "bow-<dictionary id>-none": a dictionary's words and parameters are all in its id.
  const kernels::GoodConfig& good = descriptor.good;
  std::string k = std::string(kernels::to_string(descriptor.kind)) + "-";
  if (descriptor.kind == kernels::DescriptorKind::SPIN_SET) {
    // "spin-<fnv of its specification>-none": every parameter is in describe().
    char id[17];
    std::snprintf(id, sizeof id, "%016llx",
                  static_cast<unsigned long long>(fnv1a(descriptor.describe())));
    k += std::string(id) + "-" + perturbation_name(perturbation);
  } else if (descriptor.local() && descriptor.dictionary) {
    k += kernels::dictionary_id_hex(descriptor.dictionary->id) + "-" +
         perturbation_name(perturbation);
  } else {
    k += std::string(good.mode == kernels::GoodMode::INVARIANT ? "invariant" : "reference") + "-" +
         std::to_string(good.bins) + "-" + perturbation_name(perturbation);
  }
  if (perturbation != Perturbation::NONE) {
    k += "-" + std::to_string(std::llround(amount_m * 1e6)) + "um";
  }
  if (perturbation == Perturbation::NOISE) { k += "-s" + std::to_string(seed); }
  return k;
}

bool perturb_view(const kernels::PointCloud& cloud, const ViewDescription& spec,
                  std::string_view view_key, kernels::PointCloud& out) {
  finite_points(cloud, out);
  if (spec.perturbation == Perturbation::NOISE && spec.amount_m > 0.0) {
    core::Rng rng(fnv1a(view_key, spec.seed ^ 0x9E3779B97F4A7C15ULL));
    for (std::size_t i = 0; i < out.size(); ++i) {
      out.x()[i] += static_cast<float>(spec.amount_m * rng.normal());
      out.y()[i] += static_cast<float>(spec.amount_m * rng.normal());
      out.z()[i] += static_cast<float>(spec.amount_m * rng.normal());
    }
  } else if (spec.perturbation == Perturbation::DOWNSAMPLE) {
    kernels::VoxelGridScratch scratch(out.size());
    kernels::PointCloud grid;
    grid.resize_unorganized(out.size());
    auto kept = kernels::voxel_grid(out.points(), static_cast<float>(spec.amount_m), scratch,
                                    grid.points());
    if (!kept) { return false; }
    grid.resize_unorganized(*kept);
    out = std::move(grid);
  }
  return true;
}

Result<DescriptorTable, EvalError> describe_dataset(const Dataset& dataset,
                                                    const ViewDescription& spec,
                                                    const std::filesystem::path& cache_dir,
                                                    Progress* progress, DescribeStats* stats,
                                                    std::vector<std::string>* warnings) {
  if (auto ok = check_spec(spec); !ok) { return err(ok.error()); }
  const std::size_t n = dataset.views.size();
  DescriptorTable table{spec.length(), std::vector<float>(n * spec.length(), 0.0F)};
  const std::filesystem::path file =
      cache_dir.empty() ? std::filesystem::path{} : cache_path(dataset, spec, cache_dir);
  DescriptorCache cache =
      file.empty() ? DescriptorCache{spec.length(), {}} : load_cache(file, spec.length());
  std::vector<FileStamp> stamps(n);
  const std::vector<std::uint8_t> hit = fill_from_cache(dataset, cache, stamps, table);
  std::vector<std::string> errors(n);
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, n, 8), [&](const tbb::blocked_range<std::size_t>& r) {
        kernels::Describer describer(spec.descriptor);
        for (std::size_t v = r.begin(); v != r.end(); ++v) {
          if (hit[v] == 0) {
            errors[v] = describe_one(
                dataset, v, spec, describer,
                std::span<float>(table.values).subspan(v * table.length, table.length));
          }
          if (progress != nullptr) { progress->advance(); }
        }
      });
  for (const std::string& e : errors) {
    if (!e.empty()) { return err(EvalError{EvalError::Code::BAD_VIEW, e}); }
  }
  std::size_t cached = 0;
  for (std::size_t v = 0; v < n; ++v) {
    cached += hit[v];
    if (hit[v] == 0) {
      const auto row = table.row(v);
      cache.entries[dataset.views[v].relative] =
          DescriptorCache::Entry{stamps[v], std::vector<float>(row.begin(), row.end())};
    }
  }
  if (stats != nullptr) { *stats = DescribeStats{n - cached, cached}; }
  if (!file.empty() && cached != n) {
    const std::string problem = save_descriptor_cache(cache, file);
    if (!problem.empty() && warnings != nullptr) {
      warnings->push_back("descriptor cache not saved: " + problem);
    }
  }
  return table;
}

}  // namespace orthoflow::evaluation
