// OctoMap ColorOcTree baseline for `sogmm bench`. OctoMap is an optional
// dependency: without it (SOGMM_HAVE_OCTOMAP undefined at build time)
// octomap_available() is false and constructing OctoMapModel throws.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "sogmm/point_cloud.hpp"

namespace sogmm::bench {

/// True when the bench was built with liboctomap.
bool octomap_available();
/// "1.9.7" or "not built" for messages.
const char* octomap_version();

/// A ColorOcTree of one scan. The cloud is inserted as one scan from the
/// camera origin (insertPointCloud with origin (0, 0, 0): ray casting clears
/// the free space along each ray, endpoint voxels become occupied). Each
/// occupied leaf (at the finest depth, i.e. the given resolution) keeps the
/// exact mean gray of the points that fell into it, kept beside the tree keyed
/// by OcTreeKey; the tree's own 8-bit node colour is set to that mean (round
/// to nearest) so that the .ot file holds the grayscale like the paper's.
class OctoMapModel {
 public:
  /// Throws Error(InvalidArgument) for resolution <= 0 and Error(InvalidData)
  /// when OctoMap support was not built.
  explicit OctoMapModel(double resolution);
  ~OctoMapModel();
  OctoMapModel(const OctoMapModel&) = delete;
  OctoMapModel& operator=(const OctoMapModel&) = delete;

  /// Inserts the scan (camera frame) and prunes the tree. With `ray_cast`
  /// false only the endpoint voxels are updated (no free space is stored,
  /// a much smaller .ot file). Throws Error(InvalidData) for an empty or
  /// non-finite cloud.
  void build(const PointsView& points, bool ray_cast = true);

  double resolution() const;
  /// Number of occupied leaves at the finest depth.
  std::size_t occupied_leaves() const;
  /// Number of tree nodes (inner and leaf) after pruning.
  std::size_t tree_nodes() const;

  /// Gray of the occupied leaf containing the point; if that leaf is unknown
  /// or free, the gray of the occupied leaf whose centre is nearest
  /// (`used_fallback`, if not null, is incremented).
  float gray_at(const float* xyz, std::size_t* used_fallback = nullptr) const;

  /// `n` points (rows of 3 floats): centres of the occupied leaves, each
  /// repeated in proportion to the number of points that fell into it
  /// (largest-remainder rounding; n = number of input points repeats each
  /// centre exactly its count times).
  std::vector<float> reconstruct(std::size_t n) const;

  /// Size in bytes of the .ot file written by ColorOcTree::write (full
  /// occupancy + colour), measured by writing a temporary file. Throws
  /// Error(Io) if the file cannot be written.
  std::uint64_t file_bytes() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sogmm::bench
