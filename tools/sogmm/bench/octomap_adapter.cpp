#include "octomap_adapter.hpp"

#include <cmath>

#include "ndt_map.hpp"  // proportional_allocation
#include "sogmm/error.hpp"

#ifdef SOGMM_HAVE_OCTOMAP
#include <octomap/ColorOcTree.h>
#include <octomap/octomap.h>
#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <limits>
#include <string>
#include <unordered_map>
#endif

namespace sogmm::bench {

#ifdef SOGMM_HAVE_OCTOMAP

bool octomap_available() { return true; }
#ifndef SOGMM_OCTOMAP_VERSION
#define SOGMM_OCTOMAP_VERSION "unknown version"
#endif
const char* octomap_version() { return SOGMM_OCTOMAP_VERSION; }

namespace {
struct LeafStats {
  double gray_sum = 0.0;
  std::size_t count = 0;
  bool occupied = false;
};
}  // namespace

struct OctoMapModel::Impl {
  explicit Impl(double res) : tree(res) {}
  octomap::ColorOcTree tree;
  // Exact per-leaf statistics (finest depth), in insertion order of first hit.
  std::unordered_map<octomap::OcTreeKey, std::size_t, octomap::OcTreeKey::KeyHash> index;
  std::vector<octomap::OcTreeKey> keys;
  std::vector<LeafStats> stats;
  std::vector<std::size_t> occupied;  // indices into keys/stats
};

OctoMapModel::OctoMapModel(double resolution) {
  require(std::isfinite(resolution) && resolution > 0, ErrorCode::InvalidArgument, "OctoMap resolution must be > 0");
  impl_ = std::make_unique<Impl>(resolution);
}

OctoMapModel::~OctoMapModel() = default;

double OctoMapModel::resolution() const { return impl_->tree.getResolution(); }

void OctoMapModel::build(const PointsView& points, bool ray_cast) {
  require_finite_points(points, "OctoMap input cloud");
  Impl& m = *impl_;
  octomap::Pointcloud scan;
  scan.reserve(points.size);
  for (std::size_t i = 0; i < points.size; ++i) {
    const float* p = points[i];
    octomap::OcTreeKey key;
    require(m.tree.coordToKeyChecked(octomap::point3d(p[0], p[1], p[2]), key), ErrorCode::InvalidData,
            "OctoMap: point outside the octree's range");
    auto [it, inserted] = m.index.emplace(key, m.keys.size());
    if (inserted) {
      m.keys.push_back(key);
      m.stats.emplace_back();
    }
    LeafStats& s = m.stats[it->second];
    s.gray_sum += p[3];
    ++s.count;
    scan.push_back(p[0], p[1], p[2]);
  }
  // One scan from the camera origin, ray casting, no range limit. lazy_eval
  // keeps the finest leaves until colours are set, then inner nodes are
  // updated and the tree pruned (ColorOcTree prunes only equal colours).
  if (ray_cast) {
    m.tree.insertPointCloud(scan, octomap::point3d(0, 0, 0), -1.0, /*lazy_eval=*/true, /*discretize=*/false);
  } else {
    for (const octomap::OcTreeKey& key : m.keys) m.tree.updateNode(key, true, /*lazy_eval=*/true);
  }
  m.tree.updateInnerOccupancy();
  for (std::size_t k = 0; k < m.keys.size(); ++k) {
    LeafStats& s = m.stats[k];
    const octomap::ColorOcTreeNode* node = m.tree.search(m.keys[k]);
    s.occupied = node != nullptr && m.tree.isNodeOccupied(node);
    if (!s.occupied) continue;
    m.occupied.push_back(k);
    const double g = s.gray_sum / static_cast<double>(s.count);
    const auto g8 = static_cast<std::uint8_t>(std::lround(std::min(1.0, std::max(0.0, g)) * 255.0));
    m.tree.setNodeColor(m.keys[k], g8, g8, g8);
  }
  m.tree.updateInnerOccupancy();
  m.tree.prune();
}

std::size_t OctoMapModel::occupied_leaves() const { return impl_->occupied.size(); }
std::size_t OctoMapModel::tree_nodes() const { return impl_->tree.size(); }

float OctoMapModel::gray_at(const float* xyz, std::size_t* used_fallback) const {
  const Impl& m = *impl_;
  require(!m.occupied.empty(), ErrorCode::InvalidData, "OctoMap has no occupied leaf");
  octomap::OcTreeKey key;
  if (m.tree.coordToKeyChecked(octomap::point3d(xyz[0], xyz[1], xyz[2]), key)) {
    auto it = m.index.find(key);
    if (it != m.index.end() && m.stats[it->second].occupied) {
      const LeafStats& s = m.stats[it->second];
      return static_cast<float>(s.gray_sum / static_cast<double>(s.count));
    }
  }
  if (used_fallback) ++*used_fallback;
  double best = std::numeric_limits<double>::infinity();
  std::size_t best_k = m.occupied.front();
  for (std::size_t k : m.occupied) {
    const octomap::point3d c = m.tree.keyToCoord(m.keys[k]);
    const double dx = c.x() - xyz[0], dy = c.y() - xyz[1], dz = c.z() - xyz[2];
    const double d2 = dx * dx + dy * dy + dz * dz;
    if (d2 < best) {
      best = d2;
      best_k = k;
    }
  }
  const LeafStats& s = m.stats[best_k];
  return static_cast<float>(s.gray_sum / static_cast<double>(s.count));
}

std::vector<float> OctoMapModel::reconstruct(std::size_t n) const {
  const Impl& m = *impl_;
  std::vector<std::size_t> counts;
  counts.reserve(m.occupied.size());
  for (std::size_t k : m.occupied) counts.push_back(m.stats[k].count);
  const std::vector<std::size_t> share = proportional_allocation(counts, n);
  std::vector<float> out;
  out.reserve(3 * n);
  for (std::size_t i = 0; i < m.occupied.size(); ++i) {
    const octomap::point3d c = m.tree.keyToCoord(m.keys[m.occupied[i]]);
    for (std::size_t r = 0; r < share[i]; ++r) {
      out.push_back(c.x());
      out.push_back(c.y());
      out.push_back(c.z());
    }
  }
  return out;
}

std::uint64_t OctoMapModel::file_bytes() const {
  static std::atomic<unsigned> counter{0};
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() /
      ("sogmm-bench-" + std::to_string(::getpid()) + "-" + std::to_string(counter++) + ".ot");
  const bool ok = impl_->tree.write(path.string());
  std::error_code ec;
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  std::filesystem::remove(path, ec);
  require(ok && size != static_cast<std::uintmax_t>(-1), ErrorCode::Io,
          "cannot write the temporary OctoMap file " + path.string());
  return static_cast<std::uint64_t>(size);
}

#else  // no OctoMap

bool octomap_available() { return false; }
const char* octomap_version() { return "not built"; }

struct OctoMapModel::Impl {};

OctoMapModel::OctoMapModel(double) {
  throw Error(ErrorCode::InvalidData, "this sogmm was built without OctoMap (install liboctomap-dev and rebuild)");
}
OctoMapModel::~OctoMapModel() = default;
double OctoMapModel::resolution() const { return 0.0; }
void OctoMapModel::build(const PointsView&, bool) {}
std::size_t OctoMapModel::occupied_leaves() const { return 0; }
std::size_t OctoMapModel::tree_nodes() const { return 0; }
float OctoMapModel::gray_at(const float*, std::size_t*) const { return 0.0f; }
std::vector<float> OctoMapModel::reconstruct(std::size_t) const { return {}; }
std::uint64_t OctoMapModel::file_bytes() const { return 0; }

#endif

}  // namespace sogmm::bench
