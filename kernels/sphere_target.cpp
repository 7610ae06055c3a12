#include "kernels/sphere_target.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <span>

namespace orthoflow::kernels {

namespace {

constexpr std::size_t TABLE_BITS = 20;  // 1 M slots: over three times a 640 x 480 frame's votes
constexpr std::size_t TABLE = std::size_t{1} << TABLE_BITS;
constexpr int MAX_ITERATIONS = 20;
constexpr int WIDE_ROUNDS = 3;
constexpr double DEG = 180.0 / 3.141592653589793;

using Cell = std::array<std::int64_t, 3>;

std::uint64_t cell_key(const Cell& c) noexcept {
  const auto field = [](std::int64_t v) {
    return static_cast<std::uint64_t>(v + (1 << 20)) & 0x1FFFFF;
  };
  return (field(c[0]) << 42) | (field(c[1]) << 21) | field(c[2]) | (std::uint64_t{1} << 63);
}

Cell cell_of_key(std::uint64_t key) noexcept {
  const auto unpack = [key](int shift) {
    return static_cast<std::int64_t>((key >> shift) & 0x1FFFFF) - (1 << 20);
  };
  return {unpack(42), unpack(21), unpack(0)};
}

std::size_t slot_of(std::uint64_t key) noexcept {
  return static_cast<std::size_t>((key * 0x9E3779B97F4A7C15ULL) >> (64 - TABLE_BITS));
}

/// The pixels of a frame and their centre candidates.
struct Votes {
  CloudView cloud;
  const std::vector<float>& nx;
  const std::vector<float>& ny;
  const std::vector<float>& nz;
  const SphereTargetParams& p;
  double cell;
  [[nodiscard]] bool votes(std::size_t i) const noexcept {
    const float z = cloud.points.z[i];
    return z >= p.min_range && z <= p.max_range && std::isfinite(nx[i]);
  }
  [[nodiscard]] Eigen::Vector3d candidate(std::size_t i) const noexcept {
    const double r = p.radius;
    return {cloud.points.x[i] - r * nx[i], cloud.points.y[i] - r * ny[i],
            cloud.points.z[i] - r * nz[i]};
  }
  [[nodiscard]] Cell cell_of(const Eigen::Vector3d& c) const noexcept {
    return {std::llround(std::floor(c.x() / cell)), std::llround(std::floor(c.y() / cell)),
            std::llround(std::floor(c.z() / cell))};
  }
};

/// Gauss-Newton on sum (|p - c| - r)^2 over the pixels within the tolerance on the side facing the
/// sensor, from @p centre; the first rounds take three times the tolerance (the seed may be a cell
/// off). @return the fit and, in @p facing, the fitted pixels' summed directions from the centre.
SphereTarget fit_sphere(CloudView cloud, std::span<const std::uint32_t> near,
                        const SphereTargetParams& p, Eigen::Vector3d centre,
                        Eigen::Vector3d& facing) noexcept {
  const auto& x = cloud.points.x;
  const auto& y = cloud.points.y;
  const auto& z = cloud.points.z;
  const double r = p.radius;
  SphereTarget out;
  for (int it = 0; it < MAX_ITERATIONS; ++it) {
    const double band = it < WIDE_ROUNDS ? 3.0 * p.tolerance : double{p.tolerance};
    Eigen::Matrix3d jtj = Eigen::Matrix3d::Zero();
    Eigen::Vector3d jte = Eigen::Vector3d::Zero();
    facing.setZero();
    double sq = 0.0;
    std::size_t fit = 0;
    for (const std::uint32_t i : near) {
      const Eigen::Vector3d d(x[i] - centre.x(), y[i] - centre.y(), z[i] - centre.z());
      const double len = d.norm();
      const double e = len - r;
      if (!(std::abs(e) <= band) || d.dot(centre) >= 0.0) continue;  // the far side is hidden
      const Eigen::Vector3d u = d / len;                             // de/dc = -u
      jtj += u * u.transpose();
      jte -= u * e;
      facing += u;
      sq += e * e;
      ++fit;
    }
    out.pixels = fit;
    out.rms = fit > 0 ? std::sqrt(sq / double(fit)) : 0.0;
    out.iterations = it + 1;
    if (fit < 3) break;
    const Eigen::Vector3d step = jtj.ldlt().solve(-jte);
    if (!step.allFinite()) break;
    centre += step;
    if (it >= WIDE_ROUNDS && step.norm() < 1e-6) break;
  }
  out.centre = {centre.x(), centre.y(), centre.z()};
  return out;
}

/// The radius that fits best: Gauss-Newton on sum (|p - c| - r)^2 over centre and radius, from the
/// fixed-radius fit, over the pixels within the tolerance on the side facing the sensor. A ball
/// of the radius sought gives it back; a rounded joint of the arm, a cylinder, a larger or smaller
/// ball give their own.
double free_radius(CloudView cloud, std::span<const std::uint32_t> near,
                   const SphereTargetParams& p, const SphereTarget& fixed) noexcept {
  const auto& x = cloud.points.x;
  const auto& y = cloud.points.y;
  const auto& z = cloud.points.z;
  Eigen::Vector4d t(fixed.centre[0], fixed.centre[1], fixed.centre[2], p.radius);
  for (int it = 0; it < 10; ++it) {
    Eigen::Matrix4d jtj = Eigen::Matrix4d::Zero();
    Eigen::Vector4d jte = Eigen::Vector4d::Zero();
    const Eigen::Vector3d c = t.head<3>();
    for (const std::uint32_t i : near) {
      const Eigen::Vector3d d(x[i] - c.x(), y[i] - c.y(), z[i] - c.z());
      const double len = d.norm();
      const double e = len - t[3];
      if (!(std::abs(e) <= double{p.tolerance}) || d.dot(c) >= 0.0) continue;
      Eigen::Vector4d j;
      j << -d / len, -1.0;
      jtj += j * j.transpose();
      jte += j * e;
    }
    const Eigen::Vector4d step = jtj.ldlt().solve(-jte);
    if (!step.allFinite()) return std::numeric_limits<double>::quiet_NaN();
    t += step;
    if (step.norm() < 1e-7) break;
  }
  return t[3];
}

}  // namespace

SphereTargetFinder::SphereTargetFinder(std::size_t max_points)
    : nx_(max_points),
      ny_(max_points),
      nz_(max_points),
      near_(max_points),
      keys_(TABLE, 0),
      counts_(TABLE, 0) {
  used_.reserve(std::min(max_points, TABLE / 2));
}

Result<SphereTarget, std::string> SphereTargetFinder::find(CloudView cloud,
                                                           const SphereTargetParams& p) {
  const std::size_t n = cloud.points.size();
  if (cloud.width == 0 || n != std::size_t{cloud.width} * cloud.height)
    return err(std::string("the frame is not organized (width x height pixels)"));
  if (n > nx_.size()) return err(std::string("the frame is larger than the finder was sized for"));
  if (!(p.radius > 0.0F) || !(p.tolerance > 0.0F) || !std::isfinite(p.radius))
    return err(std::string("the ball's radius and the tolerance must be positive"));
  organized_normals(cloud, p.normals, PointsSpan{nx_, ny_, nz_});
  for (const std::uint32_t s : used_) keys_[s] = 0, counts_[s] = 0;
  used_.clear();
  const Votes v{cloud, nx_, ny_, nz_, p, 0.4 * double{p.radius}};
  // 1. Votes: each pixel's centre candidate, counted per cell.
  for (std::size_t i = 0; i < n; ++i) {
    if (!v.votes(i)) continue;
    const std::uint64_t key = cell_key(v.cell_of(v.candidate(i)));
    std::size_t s = slot_of(key);
    while (keys_[s] != 0 && keys_[s] != key) s = (s + 1) & (TABLE - 1);
    if (keys_[s] == 0) {
      if (used_.size() == used_.capacity()) continue;  // full: this vote is dropped
      keys_[s] = key;
      used_.push_back(static_cast<std::uint32_t>(s));
    }
    ++counts_[s];
  }
  if (used_.empty()) return err(std::string("no pixel in range has a surface normal"));
  // 2. Seeds: the cells with the most votes, none beside a better one (ties: the lower key).
  std::array<std::pair<std::uint32_t, std::uint64_t>, SEEDS> seeds{};
  for (const std::uint32_t s : used_) {
    const std::pair<std::uint32_t, std::uint64_t> c{counts_[s], keys_[s]};
    const auto worse = [](const auto& a, const auto& b) {
      return a.first != b.first ? a.first < b.first : a.second > b.second;
    };
    if (!worse(seeds.back(), c)) continue;
    const Cell here = cell_of_key(c.second);
    const auto near = [&](const auto& seed) {
      if (seed.first == 0) return false;
      const Cell o = cell_of_key(seed.second);
      return std::abs(o[0] - here[0]) <= 1 && std::abs(o[1] - here[1]) <= 1 &&
             std::abs(o[2] - here[2]) <= 1;
    };
    const auto beside = std::find_if(seeds.begin(), seeds.end(), near);
    if (beside != seeds.end()) {
      if (!worse(*beside, c)) continue;
      std::rotate(beside, beside + 1, seeds.end());  // the neighbour gives way
      seeds.back() = {0, 0};
    }
    seeds.back() = c;
    std::sort(seeds.begin(), seeds.end(),
              [&](const auto& a, const auto& b) { return worse(b, a); });
  }
  // 3. Each seed's candidates (its cell and the 26 around it) averaged, then fitted; the fit with
  // the most pixels that passes the checks is the ball.
  Result<SphereTarget, std::string> best = err(std::string{});
  std::string why;
  for (const auto& seed : seeds) {
    if (seed.first == 0) break;
    const Cell at = cell_of_key(seed.second);
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    std::size_t votes = 0;
    for (std::size_t i = 0; i < n; ++i) {
      if (!v.votes(i)) continue;
      const Eigen::Vector3d c = v.candidate(i);
      const Cell k = v.cell_of(c);
      if (std::abs(k[0] - at[0]) > 1 || std::abs(k[1] - at[1]) > 1 || std::abs(k[2] - at[2]) > 1)
        continue;
      sum += c;
      ++votes;
    }
    // The pixels the fit may reach: within the radius, the widest band and two cells of the seed.
    const Eigen::Vector3d seed_centre = sum / double(votes);
    const double reach = p.radius + 3.0 * p.tolerance + 2.0 * v.cell;
    std::size_t m = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const double dx = cloud.points.x[i] - seed_centre.x(),
                   dy = cloud.points.y[i] - seed_centre.y(),
                   dz = cloud.points.z[i] - seed_centre.z();
      if (dx * dx + dy * dy + dz * dz <= reach * reach) near_[m++] = static_cast<std::uint32_t>(i);
    }
    const auto near = std::span<const std::uint32_t>(near_).first(m);
    Eigen::Vector3d facing;
    SphereTarget fit = fit_sphere(cloud, near, p, seed_centre, facing);
    fit.votes = votes;
    const Eigen::Vector3d centre(fit.centre[0], fit.centre[1], fit.centre[2]);
    const double tilt =
        std::acos(std::clamp(-facing.normalized().dot(centre.normalized()), -1.0, 1.0)) * DEG;
    std::string no;
    if (fit.pixels < p.min_pixels) {
      no = std::to_string(fit.pixels) + " pixels fit, " + std::to_string(p.min_pixels) + " needed";
    } else if (fit.rms > 0.5 * p.tolerance) {
      no = "the fit is loose (rms " + std::to_string(fit.rms * 1e3) + " mm)";
    } else if (const double radius = free_radius(cloud, near, p, fit);
               !(std::abs(radius - double{p.radius}) <= double{p.radius_tolerance})) {
      no = "the surface is round with a radius of " + std::to_string(radius * 1e3) + " mm";
    } else if (!(tilt <= double{p.max_cap_tilt_deg})) {
      no = "the surface does not face the sensor like a ball (" +
           std::to_string(static_cast<int>(tilt)) + " degrees off)";
    }
    if (!no.empty()) {
      if (why.empty()) why = no;  // the best-voted seed's reason
      continue;
    }
    if (best) {  // two balls: the arm's rounded parts may have the radius sought
      const Eigen::Vector3d other(best->centre[0], best->centre[1], best->centre[2]);
      if ((other - centre).norm() > double{p.radius})
        return err("two round surfaces of radius " + std::to_string(p.radius) +
                   " m in view: which one is the ball is not certain");
      if (fit.pixels <= best->pixels) continue;
    }
    best = fit;
  }
  if (best) return best;
  return err("no ball of radius " + std::to_string(p.radius) + " m: " + why);
}

}  // namespace orthoflow::kernels
