// The map's anchor (issue 36): the map holds its components relative to an
// origin and converts at its boundary (sogmm/map.hpp, Map::origin).
//
// Why: map coordinates are float32. 1000 km from the world origin a float32
// coordinate moves in steps of 6.25 cm, coarser than the surfaces a map
// holds (the same frame inserted 30 times at 500 km grew a map from 1118 to
// 9013 components). Relative to an origin near the frames they keep their
// room-scale resolution; everything summed with a pose stays in double.
#include <cfloat>
#include <cmath>
#include <string>

#include "map_state.hpp"
#include "sogmm/checked.hpp"
#include "sogmm/error.hpp"
#include "sogmm/inference.hpp"

namespace sogmm::detail {

Origin default_origin(const Pose& first_pose) {
  Origin o{};
  for (int i = 0; i < 3; ++i) o[i] = kOriginGrid * std::round(first_pose[4 * i + 3] / kOriginGrid);
  return o;
}

bool is_zero(const Origin& o) { return o[0] == 0.0 && o[1] == 0.0 && o[2] == 0.0; }

Pose anchored(const Origin& o, const Pose& camera_to_world) {
  Pose p = camera_to_world;
  for (int i = 0; i < 3; ++i) p[4 * i + 3] -= o[i];
  return p;
}

Model world_frame(const Model& anchored_model, const Origin& o) {
  Model world = anchored_model;
  Gmm& g = world.gmm;
  for (std::size_t k = 0; k < g.size(); ++k)
    for (int i = 0; i < 3; ++i) {
      float& mean = g.means[4 * k + i];
      mean = static_cast<float>(static_cast<double>(mean) + o[i]);
      require(std::isfinite(mean), ErrorCode::InvalidArgument,
              "map: component " + std::to_string(k) + " lies beyond float32 on world axis " + std::to_string(i) +
                  " (origin " + checked::exact(o[i]) + ")");
    }
  world.pose.reset();
  return world;
}

Origin split_origin(Model& model) {
  if (!model.pose) return Origin{};
  const Pose pose = *model.pose;
  model.pose.reset();
  Pose rotation = pose;
  Origin o{};
  for (int i = 0; i < 3; ++i) {
    o[i] = pose[4 * i + 3];
    rotation[4 * i + 3] = 0.0;
  }
  // A map file's pose is a translation; another world model's pose may also
  // rotate (spec/format.md 2.1), which is applied to its components.
  model.gmm = transform(model.gmm, rotation);
  return o;
}

void require_origin(const Origin& o) {
  for (int i = 0; i < 3; ++i)
    require(std::fabs(o[i]) <= FLT_MAX, ErrorCode::InvalidArgument,
            "map: origin axis " + std::to_string(i) + " is " + checked::exact(o[i]) +
                ", not finite within float32 range (world-frame exports are float32)");
}

}  // namespace sogmm::detail
