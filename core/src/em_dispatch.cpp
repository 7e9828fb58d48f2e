// Picks the EM block kernels for the running CPU.
#include <cstdlib>
#include <string>

#include "em_kernel.hpp"

namespace sogmm::detail {

#define SOGMM_DECLARE_KERNELS(isa)                                                                            \
  namespace isa {                                                                                              \
  void em_log_density(const Block&, const float*, const double*, const std::uint32_t*, std::size_t, float*,    \
                      float*, float*);                                                                         \
  double em_finish(const Block&, const float*, const double*, const std::uint32_t*, std::size_t, float*,       \
                   const float*, float*, double*, float, double*);                                              \
  void em_upper_bounds(const double*, std::size_t, const float*, double*);                                     \
  }
SOGMM_DECLARE_KERNELS(sse2)
SOGMM_DECLARE_KERNELS(avx2)
SOGMM_DECLARE_KERNELS(avx512)
#undef SOGMM_DECLARE_KERNELS

namespace {
// SOGMM_ISA=sse2|avx2 caps the choice (for benchmarks and for testing the
// narrower kernels on a wide machine); it never enables more than the CPU has.
EmKernels choose() {
  __builtin_cpu_init();
  const char* cap = std::getenv("SOGMM_ISA");
  const std::string limit = cap ? cap : "";
  if (limit != "sse2" && limit != "avx2" && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
      __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512bw"))
    return {&avx512::em_log_density, &avx512::em_finish, &avx512::em_upper_bounds, "avx512"};
  if (limit != "sse2" && __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"))
    return {&avx2::em_log_density, &avx2::em_finish, &avx2::em_upper_bounds, "avx2"};
  return {&sse2::em_log_density, &sse2::em_finish, &sse2::em_upper_bounds, "sse2"};
}
}  // namespace

const EmKernels& em_kernels() {
  static const EmKernels k = choose();
  return k;
}

}  // namespace sogmm::detail
