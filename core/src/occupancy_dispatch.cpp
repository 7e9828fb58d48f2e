// Picks the occupancy frame kernel (occupancy_kernel.hpp) for the running CPU.
#include <cstring>

#include "em_kernel.hpp"
#include "occupancy_kernel.hpp"

namespace sogmm::detail {

#define SOGMM_DECLARE_OCCUPANCY_KERNEL(isa) \
  namespace isa {                           \
  void occupancy_frame(const OccupancyFrame&, OccupancyLanes&, int); \
  }
SOGMM_DECLARE_OCCUPANCY_KERNEL(sse2)
SOGMM_DECLARE_OCCUPANCY_KERNEL(avx2)
SOGMM_DECLARE_OCCUPANCY_KERNEL(avx512)
#undef SOGMM_DECLARE_OCCUPANCY_KERNEL

OccupancyFrameFn occupancy_frame_kernel() {
  static const OccupancyFrameFn k = [] {
    const char* isa = em_kernels().isa;
    if (std::strcmp(isa, "avx512") == 0) return &avx512::occupancy_frame;
    if (std::strcmp(isa, "avx2") == 0) return &avx2::occupancy_frame;
    return &sse2::occupancy_frame;
  }();
  return k;
}

}  // namespace sogmm::detail
