#pragma once
/// @file
/// @brief The rule that matches a Kinect's motor and audio functions to its camera by USB topology
/// (specs/KINECT_V1.md 1, as libfreenect applies it). Shared by kinect_camera.cpp (serials,
/// has_motor) and kinect_motor.cpp (which motor to open). Header only; pure.
#include <vector>

#include "drivers/usb/usb_transport.hpp"

namespace orthoflow::drivers::kinect {

/// @brief The sibling of @p camera among @p candidates: the first on the same parent hub; else the
/// only one on the same bus; else the only one in the system; else nullptr (ambiguous or none).
/// @pre Every pointer in @p candidates is valid. @note Pure, never allocates; the result points
/// into @p candidates' targets.
[[nodiscard]] inline const UsbDeviceInfo* find_sibling(
    const UsbDeviceInfo& camera, const std::vector<const UsbDeviceInfo*>& candidates) noexcept {
  for (const UsbDeviceInfo* c : candidates) {
    if (same_parent_hub(camera, *c)) return c;
  }
  const UsbDeviceInfo* on_bus = nullptr;
  std::size_t count = 0;
  for (const UsbDeviceInfo* c : candidates) {
    if (c->bus == camera.bus) {
      on_bus = c;
      ++count;
    }
  }
  if (count == 1) return on_bus;
  return candidates.size() == 1 ? candidates.front() : nullptr;
}

}  // namespace orthoflow::drivers::kinect
