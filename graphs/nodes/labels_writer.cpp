#include "graphs/nodes/labels_writer.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>

#include "formats/pcd_io.hpp"
#include "kernels/frame_labels.hpp"

namespace orthoflow::graphs {

namespace {
constexpr auto POLL = std::chrono::milliseconds(2);
}  // namespace

Result<std::unique_ptr<LabelsWriter>, std::string> LabelsWriter::open(
    const std::filesystem::path& dir, std::size_t max_points, std::size_t slots) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir)) {
    return err("--labels-out " + dir.string() + ": cannot create the directory" +
               (ec ? ": " + ec.message() : std::string()));
  }
  return std::unique_ptr<LabelsWriter>(
      new LabelsWriter(dir, max_points, std::max<std::size_t>(1, slots)));
}

LabelsWriter::LabelsWriter(std::filesystem::path dir, std::size_t max_points, std::size_t slots)
    : dir_(std::move(dir)), max_points_(max_points), clouds_(slots), free_(slots), full_(slots) {
  for (std::size_t k = 0; k < slots; ++k) {
    clouds_[k].add_field(kernels::Field::LABEL);
    clouds_[k].reserve(max_points);
    (void)free_.try_push(static_cast<std::uint32_t>(k));
  }
  thread_ = std::thread([this] { loop(); });
}

LabelsWriter::~LabelsWriter() {
  flush();
  stop_.store(true);
  thread_.join();
}

bool LabelsWriter::offer(std::uint64_t frame_id, kernels::CloudView cloud,
                         const kernels::Plane& plane, float tau, const kernels::AxisBox& roi,
                         std::span<const std::int32_t> cluster_of,
                         std::span<const std::int32_t> slot_of) noexcept {
  const std::size_t n = cloud.points.size();
  std::uint32_t k = 0;
  const bool segmented = !cluster_of.empty();
  if (n > max_points_ || !cloud.organized() || (segmented && cluster_of.size() != n) ||
      !free_.try_pop(k)) {
    dropped_.fetch_add(1);
    return false;
  }
  kernels::PointCloud& c = clouds_[k];
  c.resize(cloud.width, std::max<std::uint32_t>(1, cloud.height));  // within the reserve
  std::copy(cloud.points.x.begin(), cloud.points.x.end(), c.x().begin());
  std::copy(cloud.points.y.begin(), cloud.points.y.end(), c.y().begin());
  std::copy(cloud.points.z.begin(), cloud.points.z.end(), c.z().begin());
  if (segmented) {
    kernels::frame_labels(cloud.points, plane, tau, roi, cluster_of, slot_of, c.label());
  } else {
    std::fill(c.label().begin(), c.label().end(), 0U);  // no table found: nothing labelled
  }
  c.info.frame_id = frame_id;
  queued_.fetch_add(1);
  (void)full_.try_push(k);  // never full: it holds at most the clouds that left free_
  return true;
}

bool LabelsWriter::drain() noexcept {
  std::uint32_t k = 0;
  if (!full_.try_pop(k)) return false;
  kernels::PointCloud& c = clouds_[k];
  char name[48];
  std::snprintf(name, sizeof name, "frame_%06llu.pcd",
                static_cast<unsigned long long>(c.info.frame_id));
  try {
    auto ok = formats::write_pcd(c, dir_ / name);
    if (ok) {
      written_.fetch_add(1);
    } else {
      const std::lock_guard lock(error_mutex_);
      if (first_error_.empty()) first_error_ = ok.error().to_string();
    }
  } catch (const std::exception& e) {  // std::bad_alloc from encoding: report, keep running
    const std::lock_guard lock(error_mutex_);
    if (first_error_.empty()) first_error_ = std::string("--labels-out: ") + e.what();
  }
  queued_.fetch_sub(1);
  (void)free_.try_push(k);
  return true;
}

void LabelsWriter::loop() noexcept {
  while (!stop_.load()) {
    if (!drain()) std::this_thread::sleep_for(POLL);
  }
  while (drain()) {}
}

void LabelsWriter::flush() noexcept {
  while (queued_.load() != 0) std::this_thread::sleep_for(POLL);
}

std::string LabelsWriter::first_error() const {
  const std::lock_guard lock(error_mutex_);
  return first_error_;
}

}  // namespace orthoflow::graphs
