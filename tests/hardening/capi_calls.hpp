// C API calls in the shape of the calls ABI 2 folded into others, for the
// tests (hardening, fuzz) written against them: the RGB-D calls on a frame
// made from arrays (sogmm_frame_from_arrays + sogmm_frame_set_intrinsics) and
// the fixed-K fit (SOGMM_OPT_N_COMPONENTS on a copy of the options). Each
// returns the first status that is not SOGMM_OK and frees what it made.
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

inline sogmm_status fit_fixed_k(sogmm_model** out, const float* points, std::size_t n, std::size_t k,
                                const sogmm_options* options) {
  sogmm_options* o = nullptr;
  sogmm_status s = options ? sogmm_options_clone(&o, options) : sogmm_options_create(&o);
  if (s == SOGMM_OK) s = sogmm_options_set_i64(o, SOGMM_OPT_N_COMPONENTS, static_cast<std::int64_t>(k));
  if (s == SOGMM_OK) s = sogmm_fit_points_f32(out, points, n, nullptr, o);
  sogmm_options_free(o);
  return s;
}

}  // namespace sogmm_test
