#include "model_io.hpp"

#include "file_util.hpp"
#include "sogmm/error.hpp"
#include "sogmm/fit_record.hpp"
#include "sogmm/format.hpp"

namespace sogmm::tools {

namespace {
[[noreturn]] void rethrow_with_path(const Error& e, const std::string& path) {
  const std::string what = e.what();
  if (what.find(path) != std::string::npos) throw Error(e.code(), what);
  throw Error(e.code(), path + ": " + what);
}
}  // namespace

Model load_model(const std::string& path) {
  try {
    return format::load(path);
  } catch (const Error& e) {
    rethrow_with_path(e, path);
  }
}

std::uint64_t save_model(const std::string& path, const Model& model, const format::WriteOptions& options) {
  try {
    format::save(path, model, options);
  } catch (const Error& e) {
    rethrow_with_path(e, path);
  }
  return file_size_or_zero(path);
}

Model make_model(const FitResult& result, const FitOptions& options, const Camera& camera, const DepthOptions& depth,
                 std::vector<std::pair<std::string, std::string>> key_values) {
  Model m;
  m.key_values = std::move(key_values);
  record_fit(m, result, options);  // appends the floors' keys
  m.gmm = result.gmm;
  m.camera.known = true;
  m.camera.camera = camera;
  m.camera.decimation = depth.decimate;
  m.camera.depth_scale = depth.depth_scale;
  m.camera.depth_min = depth.depth_min;
  m.camera.depth_max = depth.depth_max;
  m.producer_name = "sogmm";
  m.producer_version = version_string();
  m.created_unix_ms = unix_ms_now();
  return m;
}

std::string key_value(const Model& model, const std::string& key) {
  const std::string* v = find_value(model, key);
  return v ? *v : std::string();
}

DepthOptions depth_options_for(const CLI::App& app, const DepthOptions& flags, const Model& model) {
  DepthOptions d = flags;
  if (!model.camera.known) return d;
  if (app.count("--decimate") == 0) d.decimate = model.camera.decimation;
  if (app.count("--depth-scale") == 0) d.depth_scale = model.camera.depth_scale;
  if (app.count("--depth-min") == 0) d.depth_min = model.camera.depth_min;
  if (app.count("--depth-max") == 0) d.depth_max = model.camera.depth_max;
  validate(d);
  return d;
}

Camera camera_for(const CameraFlags& flags, const Model& model, const std::string& model_path) {
  if (camera_flags_given(flags)) return camera_from_flags(flags);
  require(model.camera.known, ErrorCode::InvalidArgument,
          model_path + ": the model stores no camera; give --intrinsics FILE or --width --height --fx --fy --cx --cy");
  validate(model.camera.camera);
  return model.camera.camera;
}

}  // namespace sogmm::tools
