#pragma once
/// @file
/// @brief What the three tabletop stage objects share (kernels/tabletop_stages.cpp,
/// kernels/table_stage.cpp, kernels/object_stage.cpp): their wall clock and the SegmentationError
/// each failure returns. Internal to kernels; never allocates.
#include <chrono>
#include <cstdint>

#include "kernels/tabletop_stages.hpp"

namespace orthoflow::kernels::detail {

using Clock = std::chrono::steady_clock;

/// @brief Milliseconds from @p start to now; @p start moves to now. @pre none.
inline double ms_since(Clock::time_point& start) noexcept {
  const auto now = Clock::now();
  const double ms = std::chrono::duration<double, std::milli>(now - start).count();
  start = now;
  return ms;
}

/// @brief The error @p code with the kernel's @p cause and its @p value. @pre none.
inline SegmentationError fail(SegmentationError::Code code, std::uint8_t cause = 0,
                              double value = 0.0) noexcept {
  return SegmentationError{code, cause, value, 0, 0};
}

}  // namespace orthoflow::kernels::detail
