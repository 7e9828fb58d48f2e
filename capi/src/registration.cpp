// sogmm_register_points_f32 and sogmm_register_model: the rigid pose of a
// point cloud or of a model against a model (issue 32), from
// sogmm/registration.hpp. The result's figures go into a
// caller-sized struct (struct_size first), so later versions can append.
#include <array>
#include <cstddef>
#include <cstring>
#include <string>

#include "internal.hpp"
#include "sogmm/registration.hpp"

namespace sogmm_capi {

// A NULL init: start at the identity.
constexpr std::array<double, 16> kIdentityPose = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

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

// The checks and outputs both registration calls share: `solve` runs the
// core's registration from the start pose with the options.
template <typename Solve>
void run_registration(const sogmm_model* target, const double* init, const sogmm_options* options,
                      double* pose_out, sogmm_registration_info* info_out, Solve solve) {
  require_nonnull(target, "target");
  require_nonnull(pose_out, "pose_out");
  require_nonnull(info_out, "info_out");
  require_registration_info_size(info_out);
  const std::array<double, 16> start = init ? require_rigid(init, "init") : kIdentityPose;
  const sogmm_options& o = opts_or_default(options);
  const sogmm::RegistrationResult r = solve(start, o);
  write_registration_info(r, info_out);
  for (int i = 0; i < 16; ++i) pose_out[i] = r.pose[i];
}

}  // namespace sogmm_capi

extern "C" {

SOGMM_API sogmm_status sogmm_register_points_f32(const sogmm_model* target, const float* points, size_t n,
                                                 const double* init, const sogmm_options* options,
                                                 double* pose_out, sogmm_registration_info* info_out) {
  SOGMM_TRY {
    sogmm_capi::require_nonnull(target, "target");
    sogmm_capi::require_nonnull(points, "points");
    sogmm_capi::run_registration(target, init, options, pose_out, info_out,
                                 [&](const std::array<double, 16>& start, const sogmm_options& o) {
                                   const auto prepared = target->registration.get(
                                       target->model.gmm, o.settings.registration, o.settings.query.threads);
                                   return sogmm::register_points(*prepared, points, n, start,
                                                                 o.settings.registration, o.settings.query.threads,
                                                                 sogmm_capi::progress_sink(o));
                                 });
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_register_model(const sogmm_model* target, const sogmm_model* source,
                                            const double* init, const sogmm_options* options, double* pose_out,
                                            sogmm_registration_info* info_out) {
  SOGMM_TRY {
    sogmm_capi::require_nonnull(target, "target");
    sogmm_capi::require_nonnull(source, "source");
    sogmm_capi::run_registration(target, init, options, pose_out, info_out,
                                 [&](const std::array<double, 16>& start, const sogmm_options& o) {
                                   const auto prepared = target->registration.get(
                                       target->model.gmm, o.settings.registration, o.settings.query.threads);
                                   return sogmm::register_model(*prepared, source->model.gmm, start,
                                                                o.settings.registration, o.settings.query.threads,
                                                                sogmm_capi::progress_sink(o));
                                 });
  }
  SOGMM_CATCH
}

}  // extern "C"
