// The frame index of occupancy (frame_index.hpp).
#include "frame_index.hpp"

#include <algorithm>
#include <cmath>

namespace sogmm::detail {

namespace {

// Cells are a quarter of the depth range on a side, and a frame is listed
// only in the cells its widened frustum meets (may_see()), not in every cell
// of its box: about a third of them, so a block lists fewer frames.
constexpr double kCellsPerDepthRange = 4.0;
// A frame whose box spans more cells than this is tested for every point
// (kept in one list), so the grid stays linear in the number of frames.
constexpr std::int64_t kMaxCellsPerFrame = 1024;
// Cell coordinates are packed in 21 bits each.
constexpr std::int64_t kCellBias = std::int64_t{1} << 20;

}  // namespace

FrameIndex::FrameIndex(const std::vector<Pose>& poses, const Camera& camera, double depth_min, double depth_max)
    : camera_(camera), depth_min_(depth_min), depth_max_(depth_max), cell_(depth_max / kCellsPerDepthRange) {
  std::vector<std::array<double, 6>> boxes;
  for (const Pose& p : poses) {
    FrameView v{};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) v.r[3 * i + j] = p[4 * j + i];
    for (int i = 0; i < 3; ++i) v.t[i] = -(v.r[3 * i] * p[3] + v.r[3 * i + 1] * p[7] + v.r[3 * i + 2] * p[11]);
    // In camera coordinates: u >= -1.5, u <= W + 0.5 (u = fx p_x / p_z + cx,
    // times p_z > 0), the same for v, and depth_min - 1 <= p_z <= depth_max + 1
    // (project() sees pixels with u in [-0.5, W - 0.5)); then in world ones.
    const double W = camera.width, H = camera.height;
    const double camera_planes[6][4] = {{camera.fx, 0, camera.cx + 1.5, 0},
                                        {-camera.fx, 0, W + 0.5 - camera.cx, 0},
                                        {0, camera.fy, camera.cy + 1.5, 0},
                                        {0, -camera.fy, H + 0.5 - camera.cy, 0},
                                        {0, 0, 1, 1.0 - depth_min},
                                        {0, 0, -1, depth_max + 1.0}};
    for (int k = 0; k < 6; ++k) {
      const double* q = camera_planes[k];
      for (int j = 0; j < 3; ++j) v.planes[k][j] = q[0] * v.r[j] + q[1] * v.r[3 + j] + q[2] * v.r[6 + j];
      v.planes[k][3] = q[0] * v.t[0] + q[1] * v.t[1] + q[2] * v.t[2] + q[3];
    }
    views_.push_back(v);
    // The frustum's box: the camera centre and the image corners at depth_max.
    std::array<double, 6> b{p[3], p[7], p[11], p[3], p[7], p[11]};
    const double us[2] = {-0.5, camera.width - 0.5}, vs[2] = {-0.5, camera.height - 0.5};
    for (double u : us)
      for (double w : vs) {
        const double c[3] = {(u - camera.cx) / camera.fx * depth_max, (w - camera.cy) / camera.fy * depth_max,
                             depth_max};
        for (int i = 0; i < 3; ++i) {
          const double x = p[4 * i] * c[0] + p[4 * i + 1] * c[1] + p[4 * i + 2] * c[2] + p[4 * i + 3];
          b[i] = std::min(b[i], x);
          b[3 + i] = std::max(b[3 + i], x);
        }
      }
    boxes.push_back(b);
  }
  if (boxes.empty()) return;
  for (int i = 0; i < 3; ++i) {
    origin_[i] = boxes[0][i];
    for (const auto& b : boxes) origin_[i] = std::min(origin_[i], b[i]);
  }
  for (std::uint32_t f = 0; f < boxes.size(); ++f) {
    std::int64_t lo[3], hi[3], cells = 1;
    for (int i = 0; i < 3; ++i) {
      lo[i] = cell(boxes[f][i], i);
      hi[i] = cell(boxes[f][3 + i], i);
      cells *= hi[i] - lo[i] + 1;
    }
    if (cells > kMaxCellsPerFrame || hi[0] >= kCellBias || hi[1] >= kCellBias || hi[2] >= kCellBias) {
      large_.push_back(f);
      continue;
    }
    for (std::int64_t i = lo[0]; i <= hi[0]; ++i)
      for (std::int64_t j = lo[1]; j <= hi[1]; ++j)
        for (std::int64_t k = lo[2]; k <= hi[2]; ++k)
          if (cell_meets(f, i, j, k)) cells_[key(i, j, k)].push_back(f);
  }
  // Every cell also lists the large frames, so a point reads one list.
  if (!large_.empty())
    for (auto& [k, list] : cells_) {
      list.insert(list.end(), large_.begin(), large_.end());
      std::sort(list.begin(), list.end());
    }
}

bool FrameIndex::cell_meets(std::uint32_t f, std::int64_t i, std::int64_t j, std::int64_t k) const {
  // The cell's box, widened by a millionth of a cell: a point on a cell's
  // border may be rounded into its neighbour by cell().
  const std::int64_t c[3] = {i, j, k};
  double lo[3], hi[3];
  for (int a = 0; a < 3; ++a) {
    lo[a] = origin_[a] + (static_cast<double>(c[a]) - 1e-6) * cell_;
    hi[a] = origin_[a] + (static_cast<double>(c[a]) + 1.0 + 1e-6) * cell_;
  }
  return may_see(f, lo, hi);
}

std::int64_t FrameIndex::cell(double v, int axis) const {
  const double c = std::floor((v - origin_[axis]) / cell_);
  return c < 0 ? -1 : static_cast<std::int64_t>(std::min(c, static_cast<double>(kCellBias)));
}

std::uint64_t FrameIndex::key(std::int64_t i, std::int64_t j, std::int64_t k) {
  return static_cast<std::uint64_t>(i) << 42 | static_cast<std::uint64_t>(j) << 21 | static_cast<std::uint64_t>(k);
}

const std::vector<std::uint32_t>* FrameIndex::candidates(const double x[3]) const {
  std::int64_t c[3];
  for (int i = 0; i < 3; ++i) {
    c[i] = cell(x[i], i);
    if (c[i] < 0 || c[i] >= kCellBias) return large_.empty() ? nullptr : &large_;
  }
  const auto it = cells_.find(key(c[0], c[1], c[2]));
  if (it != cells_.end()) return &it->second;
  return large_.empty() ? nullptr : &large_;
}

bool FrameIndex::one_cell(const double lo[3], const double hi[3]) const {
  for (int i = 0; i < 3; ++i)
    if (cell(lo[i], i) != cell(hi[i], i)) return false;
  return true;
}

// occupancy_kernel.cpp repeats this arithmetic (same operations, same order).
Projection FrameIndex::project(std::uint32_t f, const double x[3]) const {
  const FrameView& v = views_[f];
  double p[3];
  for (int i = 0; i < 3; ++i) p[i] = v.r[3 * i] * x[0] + v.r[3 * i + 1] * x[1] + v.r[3 * i + 2] * x[2] + v.t[i];
  Projection out;
  if (!(p[2] > depth_min_ && p[2] <= depth_max_)) return out;
  const double u = std::floor(camera_.fx * p[0] / p[2] + camera_.cx + 0.5);
  const double w = std::floor(camera_.fy * p[1] / p[2] + camera_.cy + 0.5);
  if (u < 0 || w < 0 || u >= camera_.width || w >= camera_.height) return out;
  out.pixel = static_cast<int>(w) * camera_.width + static_cast<int>(u);
  out.depth = p[2];
  out.ray = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) / p[2];
  return out;
}

bool FrameIndex::may_see(std::uint32_t f, const double lo[3], const double hi[3]) const {
  double c[3], h[3];
  for (int i = 0; i < 3; ++i) {
    c[i] = 0.5 * (lo[i] + hi[i]);
    h[i] = 0.5 * (hi[i] - lo[i]);
  }
  // The planes are widened by a pixel (p_z / f metres across the ray) or a
  // metre in depth, and a box is cleared only when it is more than a
  // relative 1e-9 outside (rounding here and in project() is near 1e-15 of
  // the same terms), so no frame that sees a point of the box is cleared.
  for (const auto& n : views_[f].planes) {
    const double centre = n[0] * c[0] + n[1] * c[1] + n[2] * c[2] + n[3];
    const double reach = std::abs(n[0]) * h[0] + std::abs(n[1]) * h[1] + std::abs(n[2]) * h[2];
    const double scale = std::abs(n[0] * c[0]) + std::abs(n[1] * c[1]) + std::abs(n[2] * c[2]) + std::abs(n[3]) + reach;
    if (centre + reach < -1e-9 * scale) return false;
  }
  return true;
}

BoxView FrameIndex::view(std::uint32_t f, const double lo[3], const double hi[3]) const {
  const FrameView& fv = views_[f];
  // The corners in camera coordinates as the lowest corner's image plus the
  // images of the box's edges (three products per axis instead of three per
  // corner and axis, and one division per corner below instead of two: a
  // tenth of an occupancy query was spent here). |r_ij| <= 1, so each corner
  // is within about 30 roundings of `scale` (< 1e-14 scale) of the exact
  // value, as project()'s p_z is: far inside the margin below.
  double base[3], edge[3][3], scale = 0.0;
  for (int i = 0; i < 3; ++i) {
    base[i] = fv.r[3 * i] * lo[0] + fv.r[3 * i + 1] * lo[1] + fv.r[3 * i + 2] * lo[2] + fv.t[i];
    for (int a = 0; a < 3; ++a) edge[a][i] = fv.r[3 * i + a] * (hi[a] - lo[a]);
    scale = std::max(scale, std::max(std::abs(fv.t[i]), std::max(std::abs(lo[i]), std::abs(hi[i]))));
  }
  double corner[3][8];
  for (int c = 0; c < 8; ++c)
    for (int i = 0; i < 3; ++i)
      corner[i][c] = base[i] + ((c & 1) ? edge[0][i] : 0.0) + ((c & 2) ? edge[1][i] : 0.0) + ((c & 4) ? edge[2][i] : 0.0);
  double z_lo = corner[2][0], z_hi = corner[2][0];
  for (int c = 0; c < 8; ++c) {
    z_lo = std::min(z_lo, corner[2][c]);
    z_hi = std::max(z_hi, corner[2][c]);
    for (int i = 0; i < 3; ++i) scale = std::max(scale, std::abs(corner[i][c]));
  }
  // p_z is affine in x, so the corners bound it; project() computes it, and
  // this the corners, each with an error below 1e-14 of `scale`, far inside
  // this margin.
  const double margin = 1e-9 * (1.0 + scale);
  BoxView out;
  out.z_lo = z_lo - margin;
  out.z_hi = z_hi + margin;
  if (out.z_hi <= depth_min_ || out.z_lo > depth_max_) return out;
  out.visible = true;
  if (out.z_lo <= 0.0) return out;  // the box reaches behind the camera: no pixel bound
  // The image of a box in front of the camera is the convex hull of its
  // corners' images, so the corners bound every point's (u, v) (one
  // division per corner: a few ulps, far inside the pixel of margin below).
  double u_lo = 0, u_hi = 0, w_lo = 0, w_hi = 0;
  for (int c = 0; c < 8; ++c) {
    const double inv = 1.0 / corner[2][c];
    const double u = camera_.fx * corner[0][c] * inv + camera_.cx;
    const double w = camera_.fy * corner[1][c] * inv + camera_.cy;
    u_lo = c == 0 ? u : std::min(u_lo, u);
    u_hi = c == 0 ? u : std::max(u_hi, u);
    w_lo = c == 0 ? w : std::min(w_lo, w);
    w_hi = c == 0 ? w : std::max(w_hi, w);
  }
  // Nearest pixels, one more on each side for the rounding of project().
  const auto pixel = [](double v, double limit) { return std::floor(std::clamp(v, -4.0, limit + 4.0) + 0.5); };
  const double W = camera_.width, H = camera_.height;
  const double a0 = pixel(u_lo, W) - 1, a1 = pixel(u_hi, W) + 1, b0 = pixel(w_lo, H) - 1, b1 = pixel(w_hi, H) + 1;
  if (a1 < 0 || b1 < 0 || a0 >= W || b0 >= H) {
    out.visible = false;
    return out;
  }
  out.bounded = true;
  out.seen_all = out.z_lo > depth_min_ && out.z_hi <= depth_max_ && a0 >= 0 && b0 >= 0 && a1 < W && b1 < H;
  out.u0 = static_cast<int>(std::max(a0, 0.0));
  out.v0 = static_cast<int>(std::max(b0, 0.0));
  out.u1 = static_cast<int>(std::min(a1, W - 1));
  out.v1 = static_cast<int>(std::min(b1, H - 1));
  return out;
}

}  // namespace sogmm::detail
