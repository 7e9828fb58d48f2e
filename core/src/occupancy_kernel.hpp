// One frame's occupancy evidence for a block of points (private;
// occupancy.cpp), compiled once per instruction set (occupancy_kernel.cpp,
// like query_kernel.cpp) and chosen with the EM kernels' instruction set.
//
// The kernel is the per-point loop of occupancy.cpp for one asked frame:
// project each point into the frame (FrameIndex::project), read the render's
// depth there, and add the frame's evidence (detail::Evidence) to the point's
// running sums, over the points of a block as arrays so that the loops run
// at the machine's vector width. Every value is computed with the same IEEE
// operations in the same order as the scalar code (add, subtract, multiply,
// divide, sqrt and the table's Horner form, each correctly rounded in every
// vector width; the kernels are compiled with -ffp-contract=off so no fused
// multiply-add changes a rounding), and branches become selects between
// values so computed. So the sums are bitwise those of the scalar path on
// SSE2, AVX2 and AVX-512 alike (test OccupancyBlocks.BitwiseTheAnswerOfEveryFrame
// runs under each).
#pragma once

#include <cstddef>
#include <cstdint>

namespace sogmm::detail {

/// Points per block of occupancy.cpp.
inline constexpr int kOccupancyBlock = 64;

/// A block's points and their evidence so far (detail::Evidence as arrays;
/// whole_free counts frames, exact in a double).
struct OccupancyLanes {
  alignas(64) double x[kOccupancyBlock], y[kOccupancyBlock], z[kOccupancyBlock];
  alignas(64) double unknown[kOccupancyBlock], occupied[kOccupancyBlock], free[kOccupancyBlock];
  alignas(64) double whole_free[kOccupancyBlock];
};

/// One frame as the kernel needs it.
struct OccupancyFrame {
  const double* r;  ///< world-to-camera rotation, row-major (FrameView::r)
  const double* t;  ///< world-to-camera translation (FrameView::t)
  double fx, fy, cx, cy;
  int width, height;            ///< the decimated camera
  double depth_min, depth_max;  ///< seen: depth_min < p_z <= depth_max
  const float* depth;           ///< the frame's render, width x height, NaN: no surface
  double band;                  ///< beyond this gap |p_z - D| a point's evidence is whole (occupancy.cpp)
  double thickness, sigma;      ///< OccupancyOptions
  const double* phi;            ///< PhiTable::coefficients(), four per interval
};

/// Adds frame `f`'s evidence to points 0..count-1 of `lanes`.
using OccupancyFrameFn = void (*)(const OccupancyFrame& f, OccupancyLanes& lanes, int count);

/// The kernel for this CPU (the instruction set em_kernels() chose).
OccupancyFrameFn occupancy_frame_kernel();

}  // namespace sogmm::detail
