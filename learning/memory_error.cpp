// The perceptual memory's errors (learning/perceptual_memory.hpp): their codes' names, their text,
// and memory_error(), which names the store in every message. Opening and reading the store is in
// perceptual_memory.cpp.
#include <filesystem>
#include <string>

#include "learning/detail/memory_state.hpp"
#include "learning/perceptual_memory.hpp"

namespace orthoflow::learning {
namespace {

using Code = MemoryError::Code;

}  // namespace

MemoryError memory_error(MemoryError::Code code, const std::filesystem::path& where,
                         const std::string& what) {
  return MemoryError{code, where.string() + ": " + what};
}

const char* to_string(MemoryError::Code code) noexcept {
  switch (code) {
    case Code::OPEN_FAILED:
      return "open_failed";
    case Code::PARAMS_MISMATCH:
      return "params_mismatch";
    case Code::CORRUPT:
      return "corrupt";
    case Code::WRITE_FAILED:
      return "write_failed";
    case Code::REJECTED:
      return "rejected";
    case Code::UNKNOWN_LABEL:
      return "unknown_label";
    case Code::FILE_FAILED:
      return "file_failed";
    case Code::READ_ONLY:
      return "read_only";
    case Code::BAD_IMPORT:
      return "bad_import";
  }
  return "unknown";
}

std::string MemoryError::to_string() const {
  return std::string(learning::to_string(code)) + ": " + message;
}

}  // namespace orthoflow::learning
