// Picks the registration kernels (registration_kernel.hpp) for the running CPU.
#include <cstring>

#include "em_kernel.hpp"
#include "registration_kernel.hpp"

namespace sogmm::detail {

#define SOGMM_DECLARE_REGISTRATION_KERNEL(isa)                                    \
  namespace isa {                                                                 \
  void registration_pairs(const double*, const RegistrationPairs&, std::size_t);  \
  void registration_terms(const double*, const double*, double*, std::size_t);     \
  }
SOGMM_DECLARE_REGISTRATION_KERNEL(sse2)
SOGMM_DECLARE_REGISTRATION_KERNEL(avx2)
SOGMM_DECLARE_REGISTRATION_KERNEL(avx512)
#undef SOGMM_DECLARE_REGISTRATION_KERNEL

const RegistrationKernels& registration_kernels() {
  static const RegistrationKernels k = [] {
    const char* isa = em_kernels().isa;
    if (std::strcmp(isa, "avx512") == 0) return RegistrationKernels{&avx512::registration_pairs, &avx512::registration_terms};
    if (std::strcmp(isa, "avx2") == 0) return RegistrationKernels{&avx2::registration_pairs, &avx2::registration_terms};
    return RegistrationKernels{&sse2::registration_pairs, &sse2::registration_terms};
  }();
  return k;
}

}  // namespace sogmm::detail
