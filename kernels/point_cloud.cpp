#include "kernels/point_cloud.hpp"

#include <limits>

#include "core/assert.hpp"

namespace orthoflow::kernels {

PointCloud::PointCloud(std::pmr::memory_resource* resource)
    : x_(resource),
      y_(resource),
      z_(resource),
      rgb_(resource),
      label_(resource),
      nx_(resource),
      ny_(resource),
      nz_(resource) {}

void PointCloud::resize(std::uint32_t width, std::uint32_t height) {
  // An empty cloud is always 0 x 1 (unorganized), as PCL writes it.
  const bool empty = (width == 0 || height == 0);
  width_ = empty ? 0 : width;
  height_ = empty ? 1 : height;
  resize_buffers(static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_));
}

void PointCloud::resize_unorganized(std::size_t n) {
  OF_ENFORCE(n <= std::numeric_limits<std::uint32_t>::max(), "a cloud holds at most 2^32-1 points");
  resize(static_cast<std::uint32_t>(n), 1);
}

void PointCloud::resize_buffers(std::size_t n) {
  x_.resize(n);
  y_.resize(n);
  z_.resize(n);
  if (has_rgb_) { rgb_.resize(n); }
  if (has_label_) { label_.resize(n); }
  if (has_normals_) {
    nx_.resize(n);
    ny_.resize(n);
    nz_.resize(n);
  }
}

void PointCloud::add_field(Field field) {
  const std::size_t n = size();
  switch (field) {
    case Field::RGB:
      has_rgb_ = true;
      rgb_.resize(n);
      break;
    case Field::LABEL:
      has_label_ = true;
      label_.resize(n);
      break;
    case Field::NORMALS:
      has_normals_ = true;
      nx_.resize(n);
      ny_.resize(n);
      nz_.resize(n);
      break;
  }
}

void PointCloud::remove_field(Field field) {
  switch (field) {
    case Field::RGB:
      has_rgb_ = false;
      rgb_.clear();
      break;
    case Field::LABEL:
      has_label_ = false;
      label_.clear();
      break;
    case Field::NORMALS:
      has_normals_ = false;
      nx_.clear();
      ny_.clear();
      nz_.clear();
      break;
  }
}

bool PointCloud::has(Field field) const noexcept {
  switch (field) {
    case Field::RGB:
      return has_rgb_;
    case Field::LABEL:
      return has_label_;
    case Field::NORMALS:
      return has_normals_;
  }
  return false;
}

void PointCloud::reserve(std::size_t n) {
  x_.reserve(n);
  y_.reserve(n);
  z_.reserve(n);
  if (has_rgb_) { rgb_.reserve(n); }
  if (has_label_) { label_.reserve(n); }
  if (has_normals_) {
    nx_.reserve(n);
    ny_.reserve(n);
    nz_.reserve(n);
  }
}

}  // namespace orthoflow::kernels
