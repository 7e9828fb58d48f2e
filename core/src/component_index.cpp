// The component index: a uniform hash grid over r-sigma boxes
// (sogmm/component_index.hpp).
#include "sogmm/component_index.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "sogmm/checked.hpp"
#include "sogmm/error.hpp"

namespace sogmm {
namespace {

// Cell coordinates are clamped to 21 bits each so that three pack into one
// 64-bit key. Clamping only merges far cells: every query still tests the
// exact box, so it costs time out there, never recall.
constexpr std::int64_t kCoordLimit = (std::int64_t{1} << 20) - 1;

std::uint64_t pack(std::int64_t x, std::int64_t y, std::int64_t z) {
  const auto u = [](std::int64_t v) { return static_cast<std::uint64_t>(v + kCoordLimit + 1) & 0x1FFFFF; };
  return u(x) | (u(y) << 21) | (u(z) << 42);
}

float down(double v) {
  const float f = static_cast<float>(v);
  return static_cast<double>(f) > v ? std::nextafter(f, -INFINITY) : f;
}
float up(double v) {
  const float f = static_cast<float>(v);
  return static_cast<double>(f) < v ? std::nextafter(f, INFINITY) : f;
}

}  // namespace

Box3 component_box(const Gmm& gmm, std::size_t m, double sigmas) {
  const float* mu = gmm.mean(m);
  const float* c = gmm.covariance(m);
  Box3 b;
  for (int i = 0; i < 3; ++i) {
    const double center = mu[i];
    const double half = sigmas * std::sqrt(std::max(0.0, static_cast<double>(c[5 * i])));
    // The relative pad covers the rounding of the double arithmetic above.
    const double pad = 1e-6 * (half + std::fabs(center));
    b.lo[i] = center - half - pad;
    b.hi[i] = center + half + pad;
  }
  return b;
}

ComponentIndex::ComponentIndex(double sigmas) : sigmas_(sigmas) {
  require(std::isfinite(sigmas) && sigmas > 0 && sigmas <= 100, ErrorCode::InvalidArgument,
          "component index: radius " + checked::exact(sigmas) + " sigma is not in (0, 100]");
}

void ComponentIndex::clear() {
  cell_ = 0.0;
  origin_ = {};
  built_size_ = 0;
  boxes_.clear();
  large_flag_.clear();
  large_.clear();
  cells_.clear();
}

std::int64_t ComponentIndex::cell_coord(double v, int axis) const {
  const double c = std::floor((v - origin_[axis]) / cell_);
  // NaN compares false both ways and lands on the clamp, as does +-inf.
  if (!(c > -static_cast<double>(kCoordLimit))) return -kCoordLimit;
  if (!(c < static_cast<double>(kCoordLimit))) return kCoordLimit;
  return static_cast<std::int64_t>(c);
}

bool ComponentIndex::cell_range(const Box3& b, std::array<std::int64_t, 3>& lo,
                                std::array<std::int64_t, 3>& hi) const {
  double cells = 1.0;
  for (int i = 0; i < 3; ++i) {
    lo[i] = cell_coord(b.lo[i], i);
    hi[i] = cell_coord(b.hi[i], i);
    cells *= static_cast<double>(hi[i] - lo[i] + 1);
  }
  return cells <= static_cast<double>(kMaxCellsPerComponent);
}

void ComponentIndex::insert(std::uint32_t id) {
  std::array<std::int64_t, 3> lo{}, hi{};
  if (!cell_range(boxes_[id], lo, hi)) {
    large_flag_[id] = 1;
    large_.insert(std::upper_bound(large_.begin(), large_.end(), id), id);
    return;
  }
  large_flag_[id] = 0;
  const Box3& b = boxes_[id];
  const Entry e{{down(b.lo[0]), down(b.lo[1]), down(b.lo[2])}, {up(b.hi[0]), up(b.hi[1]), up(b.hi[2])}, id};
  const auto by_id = [](const Entry& a, std::uint32_t v) { return a.id < v; };
  for (std::int64_t x = lo[0]; x <= hi[0]; ++x)
    for (std::int64_t y = lo[1]; y <= hi[1]; ++y)
      for (std::int64_t z = lo[2]; z <= hi[2]; ++z) {
        std::vector<Entry>& cell = cells_[pack(x, y, z)];
        // Ids arrive ascending except on update(): keep every cell sorted so
        // queries return ascending ids without a sort.
        if (cell.empty() || cell.back().id < id)
          cell.push_back(e);
        else
          cell.insert(std::lower_bound(cell.begin(), cell.end(), id, by_id), e);
      }
}

void ComponentIndex::erase(std::uint32_t id) {
  if (large_flag_[id]) {
    large_.erase(std::lower_bound(large_.begin(), large_.end(), id));
    return;
  }
  std::array<std::int64_t, 3> lo{}, hi{};
  cell_range(boxes_[id], lo, hi);
  for (std::int64_t x = lo[0]; x <= hi[0]; ++x)
    for (std::int64_t y = lo[1]; y <= hi[1]; ++y)
      for (std::int64_t z = lo[2]; z <= hi[2]; ++z) {
        auto it = cells_.find(pack(x, y, z));
        if (it == cells_.end()) continue;
        std::vector<Entry>& cell = it->second;
        const auto pos = std::lower_bound(cell.begin(), cell.end(), id,
                                          [](const Entry& a, std::uint32_t v) { return a.id < v; });
        if (pos != cell.end() && pos->id == id) cell.erase(pos);
        if (cell.empty()) cells_.erase(it);
      }
}

void ComponentIndex::build(const Gmm& gmm) {
  const std::size_t m = gmm.size();
  require(m <= std::numeric_limits<std::uint32_t>::max(), ErrorCode::Limit,
          "component index: " + std::to_string(m) + " components exceed 2^32 - 1");
  clear();
  boxes_.resize(m);
  large_flag_.assign(m, 0);
  std::vector<double> sides(m);
  for (std::size_t k = 0; k < m; ++k) {
    boxes_[k] = component_box(gmm, k, sigmas_);
    double side = 0.0;
    for (int i = 0; i < 3; ++i) side = std::max(side, boxes_[k].hi[i] - boxes_[k].lo[i]);
    sides[k] = side;
  }
  if (m == 0) return;
  std::nth_element(sides.begin(), sides.begin() + m / 2, sides.end());
  // The median side: a typical box then spans at most 2 cells per axis. A
  // degenerate model (all sides 0) gets 1 mm cells.
  cell_ = sides[m / 2] > 0 && std::isfinite(sides[m / 2]) ? sides[m / 2] : 1e-3;
  // Cells counted from the first box's corner keep coordinates small.
  for (int i = 0; i < 3; ++i) origin_[i] = std::isfinite(boxes_[0].lo[i]) ? boxes_[0].lo[i] : 0.0;
  cells_.reserve(2 * m);
  for (std::size_t k = 0; k < m; ++k) insert(static_cast<std::uint32_t>(k));
  built_size_ = m;
}

void ComponentIndex::add(const Gmm& gmm, std::size_t first) {
  require(first == size() && first <= gmm.size(), ErrorCode::InvalidArgument,
          "component index: add from component " + std::to_string(first) + " but " + std::to_string(size()) +
              " components are indexed and the model has " + std::to_string(gmm.size()));
  if (size() == 0 || gmm.size() >= 2 * built_size_) {
    build(gmm);
    return;
  }
  require(gmm.size() <= std::numeric_limits<std::uint32_t>::max(), ErrorCode::Limit,
          "component index: " + std::to_string(gmm.size()) + " components exceed 2^32 - 1");
  for (std::size_t k = first; k < gmm.size(); ++k) {
    boxes_.push_back(component_box(gmm, k, sigmas_));
    large_flag_.push_back(0);
    insert(static_cast<std::uint32_t>(k));
  }
}

void ComponentIndex::update(const Gmm& gmm, std::size_t m) {
  require(m < size() && m < gmm.size(), ErrorCode::InvalidArgument,
          "component index: update of component " + std::to_string(m) + " of " + std::to_string(size()));
  const auto id = static_cast<std::uint32_t>(m);
  erase(id);
  boxes_[m] = component_box(gmm, m, sigmas_);
  insert(id);
}

void ComponentIndex::query_point(const double xyz[3], std::vector<std::uint32_t>& out) const {
  Cursor fresh;
  query_point(xyz, out, fresh);
}

void ComponentIndex::query_point(const double xyz[3], std::vector<std::uint32_t>& out, Cursor& cursor) const {
  out.clear();
  if (boxes_.empty() || !std::isfinite(xyz[0]) || !std::isfinite(xyz[1]) || !std::isfinite(xyz[2])) return;
  const CellKey key = pack(cell_coord(xyz[0], 0), cell_coord(xyz[1], 1), cell_coord(xyz[2], 2));
  if (!cursor.valid_ || cursor.key_ != key) {
    const auto it = cells_.find(key);
    cursor.key_ = key;
    cursor.cell_ = it == cells_.end() ? nullptr : &it->second;
    cursor.valid_ = true;
  }
  if (cursor.cell_ != nullptr) {
    // float32 point rounded both ways, so the float test never rejects a
    // point inside the double box; the double box decides. The six float
    // comparisons are combined without branches (few entries pass).
    const float lo[3] = {down(xyz[0]), down(xyz[1]), down(xyz[2])};
    const float hi[3] = {up(xyz[0]), up(xyz[1]), up(xyz[2])};
    for (const Entry& e : *static_cast<const std::vector<Entry>*>(cursor.cell_)) {
      const bool in = (hi[0] >= e.lo[0]) & (lo[0] <= e.hi[0]) & (hi[1] >= e.lo[1]) & (lo[1] <= e.hi[1]) &
                      (hi[2] >= e.lo[2]) & (lo[2] <= e.hi[2]);
      if (in && boxes_[e.id].contains(xyz)) out.push_back(e.id);
    }
  }
  if (large_.empty()) return;
  const std::size_t cell_hits = out.size();
  for (std::uint32_t id : large_)
    if (boxes_[id].contains(xyz)) out.push_back(id);
  std::inplace_merge(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(cell_hits), out.end());
}

void ComponentIndex::query_box(const Box3& box, std::vector<std::uint32_t>& out) const {
  out.clear();
  if (boxes_.empty()) return;
  std::array<std::int64_t, 3> lo{}, hi{};
  const bool few_cells = cell_range(box, lo, hi);
  double cells = 1.0;
  for (int i = 0; i < 3; ++i) cells *= static_cast<double>(hi[i] - lo[i] + 1);
  // A box spanning more cells than there are occupied ones: scan the cells
  // (or all boxes) instead of walking an empty grid.
  if (!few_cells && cells > static_cast<double>(cells_.size())) {
    for (std::size_t k = 0; k < boxes_.size(); ++k)
      if (boxes_[k].intersects(box)) out.push_back(static_cast<std::uint32_t>(k));
    return;
  }
  // As query_point: the entries' float boxes (supersets) against the box
  // rounded outward reject most misses from contiguous memory; the double
  // boxes decide.
  const float flo[3] = {down(box.lo[0]), down(box.lo[1]), down(box.lo[2])};
  const float fhi[3] = {up(box.hi[0]), up(box.hi[1]), up(box.hi[2])};
  for (std::int64_t x = lo[0]; x <= hi[0]; ++x)
    for (std::int64_t y = lo[1]; y <= hi[1]; ++y)
      for (std::int64_t z = lo[2]; z <= hi[2]; ++z) {
        const auto it = cells_.find(pack(x, y, z));
        if (it == cells_.end()) continue;
        for (const Entry& e : it->second) {
          const bool meets = (fhi[0] >= e.lo[0]) & (flo[0] <= e.hi[0]) & (fhi[1] >= e.lo[1]) &
                             (flo[1] <= e.hi[1]) & (fhi[2] >= e.lo[2]) & (flo[2] <= e.hi[2]);
          if (meets && boxes_[e.id].intersects(box)) out.push_back(e.id);
        }
      }
  for (std::uint32_t id : large_)
    if (boxes_[id].intersects(box)) out.push_back(id);
  // One cell's ids are ascending and distinct already (cells are kept sorted).
  if (lo == hi && large_.empty()) return;
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
}

}  // namespace sogmm
