#include "kernels/organized_normals.hpp"

#include <algorithm>

#include "core/assert.hpp"
#include "kernels/detail/organized_normals_kernel.hpp"

namespace orthoflow::kernels {

namespace {

/// The border (rows and columns within s of the edge) has no normal; the inside goes to @p row.
template <class Row>
std::size_t all_rows(CloudView cloud, const NormalParams& prm, PointsSpan out, RowRange rows,
                     Row row) noexcept {
  OF_ASSERT(prm.offset >= 1, "organized_normals: offset 0");
  const std::size_t w = cloud.width, h = cloud.height, s = prm.offset;
  OF_ASSERT(cloud.points.size() == w * h && out.size() >= w * h,
            "organized_normals: cloud not width x height, or output too small");
  std::size_t written = 0;
  const std::size_t end = std::min<std::size_t>(rows.end, h);
  for (std::size_t r = rows.begin; r < end; ++r) {
    const bool inner_row = r >= s && r + s < h && w > 2 * s;
    if (!inner_row) {
      for (std::size_t c = 0; c < w; ++c) detail::set_nan(out, r * w + c);
      continue;
    }
    for (std::size_t c = 0; c < s; ++c) {
      detail::set_nan(out, r * w + c);
      detail::set_nan(out, r * w + w - 1 - c);
    }
    written += row(r, s, w - s);
  }
  return written;
}

}  // namespace

std::size_t organized_normals_scalar(CloudView cloud, const NormalParams& params, PointsSpan out,
                                     RowRange rows) noexcept {
  return all_rows(cloud, params, out, rows, [&](std::size_t r, std::size_t b, std::size_t e) {
    return detail::normals_range(cloud, params, r, b, e, out);
  });
}

std::size_t organized_normals_at(CloudView cloud, const NormalParams& params, PointsSpan out,
                                 std::span<const std::uint32_t> pixels) noexcept {
  OF_ASSERT(params.offset >= 1, "organized_normals_at: offset 0");
  const std::size_t w = cloud.width, h = cloud.height, s = params.offset;
  std::size_t written = 0;
  for (const std::uint32_t i : pixels) {
    const std::size_t r = i / w, c = i % w;
    if (r < s || r + s >= h || w <= 2 * s || c < s || c + s >= w) {
      detail::set_nan(out, i);  // all_rows' border: no normal
      continue;
    }
    written += detail::normals_range(cloud, params, r, c, c + 1, out);
  }
  return written;
}

std::size_t organized_normals(CloudView cloud, const NormalParams& params, PointsSpan out,
                              RowRange rows) noexcept {
  static auto dispatched = xsimd::dispatch<SimdArchs>(detail::OrganizedNormalsRowKernel{});
  return all_rows(cloud, params, out, rows, [&](std::size_t r, std::size_t b, std::size_t e) {
    return dispatched(cloud, params, r, b, e, out);
  });
}

}  // namespace orthoflow::kernels
