// Open3D PinholeCameraIntrinsic JSON: {"width", "height", "intrinsic_matrix"
// (9 numbers, column-major 3x3)}.
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "sogmm/camera.hpp"
#include "sogmm/error.hpp"

namespace sogmm {

Camera parse_intrinsics_json(const std::string& text, const std::string& source) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    throw Error(ErrorCode::Format, source + ": not valid JSON (" + e.what() + ")");
  }
  auto field = [&](const char* name) -> const nlohmann::json& {
    require(j.is_object() && j.contains(name), ErrorCode::Format, source + ": missing field \"" + name + "\"");
    return j.at(name);
  };
  const auto& w = field("width");
  const auto& h = field("height");
  const auto& k = field("intrinsic_matrix");
  require(w.is_number_integer() && h.is_number_integer(), ErrorCode::Format,
          source + ": \"width\" and \"height\" must be integers");
  require(k.is_array() && k.size() == 9, ErrorCode::Format,
          source + ": \"intrinsic_matrix\" must be an array of 9 numbers");
  for (const auto& v : k) require(v.is_number(), ErrorCode::Format, source + ": \"intrinsic_matrix\" must hold numbers");
  Camera c;
  c.width = w.get<int>();
  c.height = h.get<int>();
  // Column-major: [fx, 0, 0, 0, fy, 0, cx, cy, 1].
  c.fx = k[0].get<double>();
  c.fy = k[4].get<double>();
  c.cx = k[6].get<double>();
  c.cy = k[7].get<double>();
  try {
    validate(c);
  } catch (const Error& e) {
    throw Error(ErrorCode::Format, source + ": " + e.what());
  }
  return c;
}

Camera read_intrinsics_json(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  require(static_cast<bool>(in), ErrorCode::Io, path + ": cannot open intrinsics file");
  std::ostringstream buf;
  buf << in.rdbuf();
  require(!in.bad(), ErrorCode::Io, path + ": cannot read intrinsics file");
  return parse_intrinsics_json(buf.str(), path);
}

}  // namespace sogmm
