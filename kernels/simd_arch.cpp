#include "kernels/simd_arch.hpp"

namespace orthoflow::kernels {
namespace {

struct ArchName {
  template <class Arch>
  const char* operator()(Arch /*arch*/) const noexcept {
    return Arch::name();
  }
};

}  // namespace

const char* simd_arch_name() noexcept {
  static const char* name = xsimd::dispatch<SimdArchs>(ArchName{})();
  return name;
}

}  // namespace orthoflow::kernels
