// PLY export of samples and component ellipsoids (binary little-endian).
#pragma once

#include <cstddef>
#include <string>

#include "sogmm/gmm.hpp"

namespace sogmm::tools {

/// Writes n points (rows of 4 floats x, y, z, gray) as a binary
/// little-endian PLY point cloud with per-vertex properties
/// `float x, y, z, float intensity, uchar red, green, blue` (red = green =
/// blue = gray clamped to [0, 1] and scaled to 0..255; intensity is the raw
/// sampled gray). Atomic write; throws Error(Io).
void write_ply_points(const std::string& path, const float* xyzg, std::size_t n, const std::string& comment);

/// Writes one closed triangle mesh per component: the `sigmas`-sigma
/// ellipsoid of the spatial 3x3 covariance, an icosphere subdivided
/// `subdivisions` times (1: 42 vertices, 80 faces per component) mapped by
/// mu + sigmas L v (L = Cholesky factor), colored by the mean gray. Vertex
/// properties `float x, y, z, uchar red, green, blue`; faces `uchar int
/// vertex_indices`. Returns the number of vertices written.
std::size_t write_ply_ellipsoids(const std::string& path, const Gmm& gmm, double sigmas, int subdivisions,
                                 const std::string& comment);

}  // namespace sogmm::tools
