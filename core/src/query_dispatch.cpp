// Picks the query block kernels: those of the instruction set em_kernels()
// chose, so the CPU check and the SOGMM_ISA cap live in one place.
#include <cstring>

#include "em_kernel.hpp"
#include "query_kernel.hpp"

namespace sogmm::detail {

#define SOGMM_DECLARE_QUERY_KERNELS(isa)                                                                      \
  namespace isa {                                                                                              \
  void query_score3(const QueryBlock&, const double*, const std::uint32_t*, std::size_t, double*, ScoreState&); \
  void query_score4(const QueryBlock&, const double*, const std::uint32_t*, std::size_t, double*, ScoreState&); \
  void query_regress(const QueryBlock&, const double*, const std::uint32_t*, std::size_t, double*,            \
                     RegressState&);                                                                           \
  }
SOGMM_DECLARE_QUERY_KERNELS(sse2)
SOGMM_DECLARE_QUERY_KERNELS(avx2)
SOGMM_DECLARE_QUERY_KERNELS(avx512)
#undef SOGMM_DECLARE_QUERY_KERNELS

const QueryKernels& query_kernels() {
  static const QueryKernels k = [] {
    const char* isa = em_kernels().isa;
    if (std::strcmp(isa, "avx512") == 0)
      return QueryKernels{&avx512::query_score3, &avx512::query_score4, &avx512::query_regress};
    if (std::strcmp(isa, "avx2") == 0) return QueryKernels{&avx2::query_score3, &avx2::query_score4, &avx2::query_regress};
    return QueryKernels{&sse2::query_score3, &sse2::query_score4, &sse2::query_regress};
  }();
  return k;
}

}  // namespace sogmm::detail
