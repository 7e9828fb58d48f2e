// Internals shared by the C API translation units: handle definitions, the
// try/catch wrapper that turns every C++ exception into a status, and small
// argument checks. Never installed.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "sogmm/camera.hpp"
#include "sogmm/fit.hpp"
#include "sogmm/model.hpp"
#include "sogmm/options.hpp"
#include "sogmm/point_cloud.hpp"
#include "sogmm/progress.hpp"
#include "sogmm/sogmm.h"

#include "registration_cache.hpp"

// ---- handles -----------------------------------------------------------

// Every setting is a field of the core's Settings, whose option registry
// (sogmm/options.hpp) gives each key's rule and default: nothing here repeats
// them.
struct sogmm_options {
  sogmm::Settings settings;
  // progress (sogmm_options_set_progress): not a key, never stored in files
  sogmm_progress_fn progress = nullptr;
  void* progress_user_data = nullptr;
};

/// Timings of a fit run in this process (not part of the file format).
struct sogmm_fit_timings {
  bool known = false;
  std::uint64_t n_points = 0;
  double seconds_mode_count = 0.0;
  double seconds_seeding = 0.0;
  double seconds_em = 0.0;
  double seconds_total = 0.0;
  std::int64_t n_init = 1;  // runs made
  std::int64_t run = 0;     // the kept one
};

struct sogmm_model {
  sogmm::Model model;
  sogmm_fit_timings timings;
  sogmm_capi::RegistrationCache registration;  // the target prepared by the last registration to this model
};

struct sogmm_buffer {
  std::vector<std::uint8_t> bytes;
};

namespace sogmm_capi {

/// Thrown inside the C API for argument problems detected by the wrapper
/// itself; carries the status directly.
struct StatusError {
  sogmm_status status;
  std::string message;
};

[[noreturn]] void fail(sogmm_status status, const std::string& message);

/// Clears the thread's last-error message (on entry of every fallible call).
void clear_error() noexcept;
/// Sets the thread's last-error message and returns `status`.
sogmm_status set_error(sogmm_status status, const char* message) noexcept;
/// Maps the exception being handled (call only inside a catch block) to a
/// status and message.
sogmm_status handle_current_exception() noexcept;

/// Milliseconds since 1970 UTC, for Model::created_unix_ms.
std::int64_t creation_time_now();

/// The options' progress callback as a core sink (empty without one).
sogmm::ProgressSink progress_sink(const sogmm_options& o);

/// Shared defaults for "NULL options".
const sogmm_options& default_options();
inline const sogmm_options& opts_or_default(const sogmm_options* o) {
  return o ? *o : default_options();
}

inline void require_nonnull(const void* p, const char* name) {
  if (!p) fail(SOGMM_E_NULL_ARG, std::string(name) + " is NULL");
}

/// SOGMM_E_INVALID_DATA unless all `count` floats are finite.
void require_finite(const float* values, std::size_t count, const char* what);

/// The 16 doubles as a pose; SOGMM_E_INVALID_ARG naming the problem unless
/// sogmm::rigid_pose_error accepts them (the one pose rule of the library).
std::array<double, 16> require_rigid(const double* pose, const char* what);

/// SOGMM_E_INVALID_ARG when info_out->struct_size is smaller than this
/// library's sogmm_registration_info (info_out not NULL).
void require_registration_info_size(const sogmm_registration_info* info_out);
/// Writes `r`'s figures into the caller-sized struct (only its first
/// struct_size bytes: later versions append fields).
void write_registration_info(const sogmm::RegistrationResult& r, sogmm_registration_info* info_out);

/// An RGB-D frame checked and back-projected as sogmm_fit_frame,
/// sogmm_map_insert_frame and sogmm_frame_to_points_f32 take it.
struct RgbdPoints {
  sogmm::Camera camera;             // full-size intrinsics
  sogmm::DepthOptions depth;        // scale, range, decimation from the options
  sogmm::PointCloud cloud;          // valid pixels of the decimated frame, row by row
};
/// Checks the frame's intrinsics and the options (SOGMM_E_NULL_ARG /
/// INVALID_ARG / LIMIT / INVALID_DATA for non-finite float gray) and
/// back-projects; the cloud may be empty. A frame without a colour image has
/// gray 0.
RgbdPoints backproject_frame(const sogmm_frame* frame, const sogmm_options& options);

/// SOGMM_E_INVALID_ARG "depth range: SOGMM_OPT_DEPTH_MIN = a must be <
/// SOGMM_OPT_DEPTH_MAX = b" unless min < max (a rule across two keys, checked
/// when the options are used).
void require_depth_range(const sogmm_options& o);

/// The fit keys of `o` as FitOptions with n_components = k (sogmm_fit_* and
/// sogmm_map_*).
sogmm::FitOptions fit_options(const sogmm_options& o, std::size_t k);

/// Stores NULL into a handle out-pointer if it is not NULL (on failure).
template <typename T>
inline void reset_out(T** out) noexcept {
  if (out) *out = nullptr;
}

/// The start of every call that returns a handle through `out`: stores NULL
/// into it (so that a failed call leaves NULL), then SOGMM_E_NULL_ARG
/// "out is NULL" if there is nowhere to store.
template <typename T>
inline void require_out(T** out) {
  reset_out(out);
  require_nonnull(out, "out");
}

}  // namespace sogmm_capi

/// Body wrapper: clears the last error, runs the statements, returns
/// SOGMM_OK; any exception becomes a status. Use as
///   SOGMM_TRY { ...; } SOGMM_CATCH
#define SOGMM_TRY            \
  sogmm_capi::clear_error(); \
  try
#define SOGMM_CATCH                                    \
  catch (...) {                                        \
    return sogmm_capi::handle_current_exception();     \
  }                                                    \
  return SOGMM_OK;
