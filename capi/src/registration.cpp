// sogmm_register_points_f32: the rigid pose of a point cloud against a model
// (issue 32), from sogmm/registration.hpp. The result's figures go into a
// caller-sized struct (struct_size first), so later versions can append.
#include <array>
#include <cstddef>
#include <cstring>
#include <string>

#include "internal.hpp"
#include "sogmm/registration.hpp"

namespace sogmm_capi {

void require_registration_info_size(const sogmm_registration_info* info_out) {
  if (info_out->struct_size < offsetof(sogmm_registration_info, eigen_ratio) + sizeof(info_out->eigen_ratio))
    fail(SOGMM_E_INVALID_ARG, "info_out->struct_size " + std::to_string(info_out->struct_size) +
                                  " is smaller than this library's sogmm_registration_info (" +
                                  std::to_string(sizeof(sogmm_registration_info)) +
                                  " bytes): set it to sizeof(sogmm_registration_info)");
}

void write_registration_info(const sogmm::RegistrationResult& r, sogmm_registration_info* info_out) {
  // Fields past this library's struct are the caller's: only ours are written.
  sogmm_registration_info info{};
  info.struct_size = info_out->struct_size;
  info.status = static_cast<int32_t>(r.status);
  info.iterations = r.iterations;
  info.log_likelihood = r.log_likelihood;
  info.inlier_ratio = r.inlier_ratio;
  info.rmse = r.rmse;
  for (int i = 0; i < 36; ++i) info.information[i] = r.information[i];
  info.unobservable = r.unobservable;
  info.eigen_ratio = r.eigen_ratio;
  std::memcpy(info_out, &info, sizeof info < info_out->struct_size ? sizeof info : info_out->struct_size);
}

}  // namespace sogmm_capi

extern "C" {

SOGMM_API sogmm_status sogmm_register_points_f32(const sogmm_model* target, const float* points, size_t n,
                                                 const double* init, const sogmm_options* options,
                                                 double* pose_out, sogmm_registration_info* info_out) {
  SOGMM_TRY {
    sogmm_capi::require_nonnull(target, "target");
    sogmm_capi::require_nonnull(points, "points");
    sogmm_capi::require_nonnull(pose_out, "pose_out");
    sogmm_capi::require_nonnull(info_out, "info_out");
    sogmm_capi::require_registration_info_size(info_out);
    constexpr std::array<double, 16> kIdentity = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    const std::array<double, 16> start = init ? sogmm_capi::require_rigid(init, "init") : kIdentity;
    const sogmm_options& o = sogmm_capi::opts_or_default(options);
    const sogmm::RegistrationResult r =
        sogmm::register_points(target->model.gmm, points, n, start, o.settings.registration,
                               o.settings.query.threads, sogmm_capi::progress_sink(o));
    sogmm_capi::write_registration_info(r, info_out);
    for (int i = 0; i < 16; ++i) pose_out[i] = r.pose[i];
  }
  SOGMM_CATCH
}

}  // extern "C"
