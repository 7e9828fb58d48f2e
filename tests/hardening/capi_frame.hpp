// The RGB-D calls of the C API on a frame made from arrays
// (sogmm_frame_from_arrays + sogmm_frame_set_intrinsics), for the tests that
// give a frame as arrays and scalars: each returns the first status that is
// not SOGMM_OK and frees the frame.
#pragma once

#include <cstddef>
#include <cstdint>

#include "sogmm/sogmm.h"

namespace sogmm_test {

struct ArrayFrame {
  sogmm_frame* frame = nullptr;
  sogmm_status status = SOGMM_OK;
  ArrayFrame(const std::uint16_t* depth, const void* color, std::int32_t format, std::uint32_t w, std::uint32_t h,
             double fx, double fy, double cx, double cy) {
    status = sogmm_frame_from_arrays(&frame, w, h, depth, color, format);
    if (status == SOGMM_OK) status = sogmm_frame_set_intrinsics(frame, fx, fy, cx, cy);
  }
  ~ArrayFrame() { sogmm_frame_free(frame); }
  ArrayFrame(const ArrayFrame&) = delete;
  ArrayFrame& operator=(const ArrayFrame&) = delete;
};

inline sogmm_status fit_rgbd(sogmm_model** out, const std::uint16_t* depth, const void* color, std::int32_t format,
                             std::uint32_t w, std::uint32_t h, double fx, double fy, double cx, double cy,
                             const sogmm_options* options) {
  const ArrayFrame f(depth, color, format, w, h, fx, fy, cx, cy);
  return f.status != SOGMM_OK ? f.status : sogmm_fit_frame(out, f.frame, options);
}

inline sogmm_status map_insert_rgbd(sogmm_map* map, const std::uint16_t* depth, const void* color,
                                    std::int32_t format, std::uint32_t w, std::uint32_t h, double fx, double fy,
                                    double cx, double cy, const double* pose) {
  const ArrayFrame f(depth, color, format, w, h, fx, fy, cx, cy);
  return f.status != SOGMM_OK ? f.status : sogmm_map_insert_frame(map, f.frame, pose);
}

inline sogmm_status rgbd_to_points(float* out, std::size_t capacity, std::size_t* n, const std::uint16_t* depth,
                                   const void* color, std::int32_t format, std::uint32_t w, std::uint32_t h, double fx,
                                   double fy, double cx, double cy, const sogmm_options* options) {
  const ArrayFrame f(depth, color, format, w, h, fx, fy, cx, cy);
  return f.status != SOGMM_OK ? f.status : sogmm_frame_to_points_f32(out, capacity, n, f.frame, options);
}

}  // namespace sogmm_test
