// Reading and writing .sogmm models from the tool, with the tool's metadata.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "cli_common.hpp"
#include "sogmm/file_options.hpp"
#include "sogmm/model.hpp"

namespace sogmm::tools {

/// Loads and verifies a .sogmm file; errors name the file (Io -> exit 4,
/// Format/InvalidData/Numeric -> exit 3).
Model load_model(const std::string& path);
/// Saves atomically (format::save) with `options`; returns the file size in bytes.
std::uint64_t save_model(const std::string& path, const Model& model, const format::WriteOptions& options = {});

/// A Model around a fit: its fit record (record_fit), CameraInfo
/// (full-resolution intrinsics, decimation, depth scale and range), producer
/// "sogmm" + library version, creation time now, and the given key/value
/// pairs (e.g. source files).
Model make_model(const FitResult& result, const FitOptions& options, const Camera& camera, const DepthOptions& depth,
                 std::vector<std::pair<std::string, std::string>> key_values);

/// The value of a key in the model's key_values ("" when absent).
std::string key_value(const Model& model, const std::string& key);

/// Depth options for evaluating or rendering `model`: the flags that were
/// given on the command line (see any_given), the rest from the model's
/// CameraInfo when known, else the flag defaults.
DepthOptions depth_options_for(const CLI::App& app, const DepthOptions& flags, const Model& model);

/// The full-resolution camera for `model`: from the flags when given, else
/// from the model's CameraInfo; throws Error(InvalidArgument) when neither.
Camera camera_for(const CameraFlags& flags, const Model& model, const std::string& model_path);

}  // namespace sogmm::tools
