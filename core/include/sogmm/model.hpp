// A fitted model with the metadata a user needs later (what the .sogmm file stores).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "sogmm/camera.hpp"
#include "sogmm/gmm.hpp"

namespace sogmm {

/// How the model was fitted and how the fit ended. A default-constructed
/// value means "unknown" (e.g. a model built from arrays).
struct FitInfo {
  bool known = false;              ///< false: the model was not produced by a fit
  double bandwidth = 0.0;          ///< mean-shift bandwidth; 0 for a fixed-K fit
  std::uint64_t n_components_requested = 0;  ///< K of a fixed-K fit; 0 = self-organizing
  double tol = 0.0;
  double reg_covar = 0.0;
  std::int32_t max_iter = 0;
  std::int32_t n_iter = 0;         ///< EM iterations run
  bool converged = false;
  double log_likelihood = 0.0;     ///< final mean log-likelihood per point
  std::uint64_t seed = 0;
};

/// The camera and depth conversion the model's points came from.
struct CameraInfo {
  bool known = false;
  Camera camera;                   ///< full-resolution intrinsics
  // The defaults are DepthOptions' (one copy, the option registry's).
  std::int32_t decimation = DepthOptions{}.decimate;
  double depth_scale = DepthOptions{}.depth_scale;
  double depth_min = DepthOptions{}.depth_min;
  double depth_max = DepthOptions{}.depth_max;
};

/// A model plus metadata. The Gmm is what all numerical operations use.
struct Model {
  Gmm gmm;
  FitInfo fit;
  CameraInfo camera;
  /// Camera-to-world pose, row-major 4x4 rigid transform, if known.
  std::optional<std::array<double, 16>> pose;
  std::string producer_name = "sogmm";
  std::string producer_version;    ///< filled by the writer when empty
  std::int64_t created_unix_ms = 0;  ///< creation time, ms since 1970 UTC; 0 = unknown
  std::vector<std::pair<std::string, std::string>> key_values;  ///< free-form metadata
};

/// Tolerance of every check that a pose is a rigid transform: the C API's
/// sogmm_model_set_pose and sogmm_model_transform, transform() below, the
/// .sogmm writer and reader (normative in spec/format.md section 9) and the
/// tools' trajectories all use rigid_pose_error(), so a pose accepted by one is
/// accepted by all. 1e-3 is the file format's value: loose enough for rotations
/// printed with a few digits or stored as float32, tight enough that R is a
/// rotation to within a 0.1 % scale.
inline constexpr double kPoseTolerance = 1e-3;

/// Empty when `pose` (row-major 4x4, [R t; 0 0 0 1]) is a rigid transform:
/// every entry finite, last row exactly (0, 0, 0, 1), |R^T R - I| <=
/// kPoseTolerance entrywise and det R > 0. Otherwise what is wrong, with the
/// offending value at round-trip precision.
std::string rigid_pose_error(const std::array<double, 16>& pose);

/// The row-major product a * b of two 4x4 poses (a after b).
std::array<double, 16> compose_poses(const std::array<double, 16>& a, const std::array<double, 16>& b);

/// The inverse of a rigid pose [R t; 0 0 0 1]: [R^T -R^T t; 0 0 0 1]. The
/// pose is not checked (see rigid_pose_error()).
std::array<double, 16> inverse_rigid(const std::array<double, 16>& pose);

/// Key of Model::key_values naming the frame of the means: absent or
/// "camera" (the camera frame), "world" (spec/format.md section 2.1).
inline constexpr const char* kCoordinateFrameKey = "coordinate_frame";
/// Key of Model::key_values counting the fits a merged model holds (decimal,
/// >= 2; spec/format.md section 2.2).
inline constexpr const char* kMergedFitsKey = "merged_fits";

/// Model::key_values by key: the one mechanism every reader and writer of the
/// metadata uses (the C API's get/set, the CLI, merge, the map's provenance).
/// The value of the first entry with `key`, or nullptr when there is none.
const std::string* find_value(const Model& model, const std::string& key);
/// Sets `key` to `value`: the first entry with `key` is replaced, else one is
/// appended (order of the other entries kept).
void set_value(Model& model, const std::string& key, std::string value);
/// Removes every entry with `key`.
void erase_value(Model& model, const std::string& key);

/// The frame of a model: the value of its first coordinate_frame key, or "camera".
std::string coordinate_frame(const Model& model);

/// The merge of spec/format.md section 2.2: merge(a.gmm, b.gmm) (see
/// sogmm/inference.hpp) with its metadata. The fit record is kept when both
/// fits used the same settings, with n_iter summed (saturating), converged
/// only if both did and log_likelihood weighted by support size; the camera
/// when both are equal; no pose; key_values are coordinate_frame (unless
/// "camera") and merged_fits (the fits of a plus those of b). Models in
/// different frames -> Error(InvalidArgument); the Gmm rules as merge().
Model merge(const Model& a, const Model& b);

/// Library version, "MAJOR.MINOR.PATCH".
const char* version_string();

}  // namespace sogmm
