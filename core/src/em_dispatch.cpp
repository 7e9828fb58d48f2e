// Picks the EM block kernel for the running CPU.
#include "em_kernel.hpp"

#include <cstdlib>
#include <string>

namespace sogmm::detail {
namespace sse2 {
double em_block(const float* const[4], int, const float*, const std::uint32_t*, std::size_t, float*, double*);
}
namespace avx2 {
double em_block(const float* const[4], int, const float*, const std::uint32_t*, std::size_t, float*, double*);
}
namespace avx512 {
double em_block(const float* const[4], int, const float*, const std::uint32_t*, std::size_t, float*, double*);
}

namespace {
struct Choice {
  EmBlockFn fn;
  const char* name;
};
// SOGMM_ISA=sse2|avx2 caps the choice (for benchmarks and for testing the
// narrower kernels on a wide machine); it never enables more than the CPU has.
Choice choose() {
  __builtin_cpu_init();
  const char* cap = std::getenv("SOGMM_ISA");
  const std::string limit = cap ? cap : "";
  if (limit == "sse2") return {&sse2::em_block, "sse2"};
  if (limit != "avx2" && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx512dq") &&
      __builtin_cpu_supports("avx512bw"))
    return {&avx512::em_block, "avx512"};
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) return {&avx2::em_block, "avx2"};
  return {&sse2::em_block, "sse2"};
}
const Choice& chosen() {
  static const Choice c = choose();
  return c;
}
}  // namespace

EmBlockFn em_block_kernel() { return chosen().fn; }
const char* em_kernel_isa() { return chosen().name; }

}  // namespace sogmm::detail
