// FrameError (graphs/frame/frame_block.hpp): the typed per-frame error and its one rule (first
// error wins); the names of the Gravity sources.
#include <string>

#include "graphs/frame/frame_block.hpp"

namespace orthoflow::graphs {

std::string_view gravity_name(Gravity g) noexcept {
  switch (g) {
    case Gravity::NONE:
      return "none";
    case Gravity::SENSOR:
      return "sensor";
    case Gravity::CONFIGURED:
      return "configured";
  }
  return "none";
}

std::string_view FrameError::name(Code code) noexcept {
  switch (code) {
    case FrameError::Code::NONE:
      return "NONE";
    case FrameError::Code::FRAME_TOO_LARGE:
      return "FRAME_TOO_LARGE";
    case FrameError::Code::FILE_UNREADABLE:
      return "FILE_UNREADABLE";
    case FrameError::Code::INVALID_FRAME:
      return "INVALID_FRAME";
    case FrameError::Code::SEGMENTATION:
      return "SEGMENTATION";
  }
  return "UNKNOWN";
}

bool FrameError::set(Code c, std::string_view node, std::uint8_t why, double number) noexcept {
  if (!empty() || c == Code::NONE) return false;
  code = c;
  cause = why;
  value = number;
  stage.assign(node);
  return true;
}

bool FrameError::set(std::string_view node, const kernels::SegmentationError& e) noexcept {
  if (!set(Code::SEGMENTATION, node, static_cast<std::uint8_t>(e.code), e.value)) return false;
  segmentation = e;
  return true;
}

std::string FrameError::to_string() const {
  std::string out = std::string(stage.view()) + ": " + std::string(name(code));
  switch (code) {
    case Code::NONE:
      return "no error";
    case Code::SEGMENTATION:
      return out + ": " + segmentation.to_string();
    case Code::FRAME_TOO_LARGE:
      return out + ": " + std::to_string(static_cast<std::uint64_t>(value)) + " points";
    case Code::FILE_UNREADABLE:
      return out + ": " + std::string(detail.view());
    case Code::INVALID_FRAME:
      return out + ": frame error " + std::to_string(cause);
  }
  return out;
}

}  // namespace orthoflow::graphs
