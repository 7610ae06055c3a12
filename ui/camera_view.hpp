#pragma once
/// @file
/// @brief The page's camera image: a graphs::CameraImage (the tap's downsampled frame) drawn as a
/// PNG, in colour when the frame has colour and as colourised depth otherwise, with each tracked
/// object's box, track id, label or "Unknown" and score. The boxes come from the objects' 3D boxes
/// projected through the camera's pinhole model, which is fitted to the image's own points (each
/// pixel's ray x/z, y/z against its column and row), so no calibration needs to be configured.
/// Runs on the server's threads, never on the frame path.
#include <cstdint>
#include <string>
#include <vector>

#include "graphs/nodes/camera_tap.hpp"
#include "ui/ui_backend.hpp"

namespace orthoflow::ui {

/// @brief Image column = fx * x / z + cx, row = fy * y / z + cy (image pixels). ok: fitted from at
/// least 64 measured pixels with an RMS residual under half a pixel (a pinhole camera's grid).
struct PinholeFit {
  bool ok = false;
  double fx = 0, cx = 0, fy = 0, cy = 0;
  double rms_px = 0;
};

[[nodiscard]] PinholeFit fit_pinhole(const graphs::CameraImage& image) noexcept;

/// @brief A tracked object's box in the image (pixels, clamped to it).
struct ImageBox {
  std::uint64_t track = 0;
  float u0 = 0, v0 = 0, u1 = 0, v1 = 0;
};

/// @brief The boxes of @p objects (tracked, not fragments, in front of the camera and overlapping
/// the image) under @p fit, in @p objects' order; empty when the fit is not ok.
[[nodiscard]] std::vector<ImageBox> project_boxes(const PinholeFit& fit, std::uint32_t width,
                                                  std::uint32_t height,
                                                  const std::vector<ObjectView>& objects);

/// @brief Loads the fonts the labels are drawn with (fontconfig reads its configuration and cache
/// on first use: some 100 ms of CPU). Call once before the frames that matter, on a thread with a
/// full-size stack.
void prepare_camera_fonts() noexcept;

/// @brief The PNG of @p image with the boxes of @p objects drawn on it; "" if cairo fails.
[[nodiscard]] std::string render_camera_png(const graphs::CameraImage& image,
                                            const std::vector<ObjectView>& objects);

}  // namespace orthoflow::ui
