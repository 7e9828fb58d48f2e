// The sogmm_map handle, shared by map.cpp (create, insert, flush, files) and
// map_queries.cpp (score, regress, sample). Never installed.
#pragma once

#include "internal.hpp"
#include "sogmm/map.hpp"

struct sogmm_map {
  sogmm::Map map;
  sogmm_options options;  ///< the creation options: RGB-D keys and progress callback of later inserts
};
