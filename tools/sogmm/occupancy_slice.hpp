// `sogmm render --occupancy`: what a map says is free, occupied or unknown on
// a horizontal slice, beside what it shows from one of its frames, so that a
// user looks at the map's occupancy before trusting its numbers.
#pragma once

#include <limits>
#include <string>

#include "sogmm/map.hpp"

namespace sogmm::tools {

/// Where the slice lies and how fine it is.
struct SliceFlags {
  std::string axis;     ///< "x", "y" or "z": the slice's normal; "" = the frames' mean up axis
  double height = std::numeric_limits<double>::quiet_NaN();  ///< position along `axis` (m); NaN = the frames' mean camera position there
  double cell = 0.02;   ///< edge of a slice pixel (m)
  int frame = 0;        ///< the map frame whose view goes beside the slice
  int threads = 0;
};

/// Writes the picture to `output` (PNG) and prints one line naming what it
/// shows and the share of free, occupied and unknown cells. The slice spans
/// the map's component means in the other two axes (plus 10%), at most
/// 1024 cells a side (the cell grows to fit). Errors: a map without frames or
/// camera record, a bad axis, cell or frame -> Error(InvalidArgument) naming it.
void write_occupancy_picture(const Map& map, const SliceFlags& flags, const std::string& output,
                             const std::string& map_name);

}  // namespace sogmm::tools
