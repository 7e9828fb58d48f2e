// The expected-surface renderer and point rendering (sogmm/render.hpp).
#include "sogmm/render.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include "parallel.hpp"
#include "progress.hpp"
#include "render_tiles.hpp"
#include "sogmm/checked.hpp"
#include "sogmm/error.hpp"
#include "sogmm/fit.hpp"
#include "sogmm/inference.hpp"
#include "sogmm/model.hpp"

namespace sogmm {

namespace {

constexpr float kEmpty = std::numeric_limits<float>::quiet_NaN();

// Rows per progress step: a report (and a cancel check) after each block.
constexpr int kRowsPerBlock = 8;

// Images of `camera`'s size, every pixel empty. At most kMaxPoints pixels
// (Error(Limit)), the bound of a frame's back-projection: a rendering holds
// three float images and a point per shown pixel.
RenderedImages empty_images(const Camera& camera) {
  const std::size_t pixels = checked::mul<std::size_t>(static_cast<std::size_t>(camera.width),
                                                       static_cast<std::size_t>(camera.height), "image pixels");
  require(pixels <= kMaxPoints, ErrorCode::Limit,
          "render: " + std::to_string(camera.width) + " x " + std::to_string(camera.height) + " pixels exceed " +
              std::to_string(kMaxPoints));
  RenderedImages r;
  r.width = camera.width;
  r.height = camera.height;
  r.depth.assign(pixels, kEmpty);
  r.gray.assign(pixels, kEmpty);
  r.variance.assign(pixels, kEmpty);
  return r;
}

// Fills gray and variance at the pixels whose depth is set, by regressing
// gray at their 3-D points (back-projected through `camera`).
void regress_at_depths(const Gmm& gmm, const Camera& camera, int threads, RenderedImages& r) {
  std::vector<float> xyz;
  std::vector<std::size_t> where;
  for (std::size_t i = 0; i < r.depth.size(); ++i) {
    if (std::isnan(r.depth[i])) continue;
    const int u = static_cast<int>(i % static_cast<std::size_t>(camera.width));
    const int v = static_cast<int>(i / static_cast<std::size_t>(camera.width));
    const double z = r.depth[i];
    xyz.push_back(static_cast<float>((u - camera.cx) / camera.fx * z));
    xyz.push_back(static_cast<float>((v - camera.cy) / camera.fy * z));
    xyz.push_back(static_cast<float>(z));
    where.push_back(i);
  }
  if (where.empty()) return;
  std::vector<float> gray(where.size()), variance(where.size());
  QueryOptions q;
  q.threads = threads;
  regress_gray(gmm, xyz.data(), where.size(), gray.data(), variance.data(), q);
  for (std::size_t k = 0; k < where.size(); ++k) {
    r.gray[where[k]] = gray[k];
    r.variance[where[k]] = std::max(variance[k], 0.f);
  }
}

// One component's 1-D Gaussian along a ray: centre t, precision a, log scale,
// and r, the squared Mahalanobis distance of the ray to the component's mean.
struct RayTerm {
  double t, a, log_c, r;
};

// RenderOptions::surface_sigma: the evidence sum_i exp(-D_i^2 / 2) at the
// mode's 3-D point (D_i its Mahalanobis distance to component i, so each
// component counts 1 at its mean whatever its weight). A flat component
// fitted to a uniform patch of surface points has the patch's edge at 2 sigma
// (a disc; sqrt(3) sigma for a square): a ray that only grazes its tail past
// the silhouette of the surface it models sees no point of it, while inside a
// surface tiled by components the evidences add up.
double surface_evidence(const std::vector<RayTerm>& terms, double t) {
  double e = 0;
  for (const RayTerm& q : terms) e += std::exp(-0.5 * (q.r + q.a * (t - q.t) * (t - q.t)));
  return e;
}

// Components within this squared Mahalanobis distance of a ray shape its 1-D
// mixture: those within max_mahalanobis, and at least those within 8 sigma.
double shaping_radius2(const RenderOptions& o) { return std::max(o.max_mahalanobis * o.max_mahalanobis, 64.0); }

// The depth of the first surface along the ray t d (see render_expected_surface),
// or NaN, from the components `ids` (ascending; a superset of those within
// shaping_radius2 of the ray). `terms` and `starts` are scratch.
float first_surface(const std::vector<RayComponent>& comps, const std::vector<std::uint32_t>& ids, const double d[3],
                    const RenderOptions& o, std::vector<RayTerm>& terms, std::vector<double>& starts) {
  const double r_show = o.max_mahalanobis * o.max_mahalanobis;
  const double r_use = shaping_radius2(o);
  terms.clear();
  starts.clear();
  for (std::uint32_t id : ids) {
    const RayComponent& c = comps[id];
    const double a = c.p[0] * d[0] * d[0] + c.p[3] * d[1] * d[1] + c.p[5] * d[2] * d[2] +
                     2 * (c.p[1] * d[0] * d[1] + c.p[2] * d[0] * d[2] + c.p[4] * d[1] * d[2]);
    const double b = c.pm[0] * d[0] + c.pm[1] * d[1] + c.pm[2] * d[2];
    const double t = b / a;
    const double r = c.mpm - b * b / a;  // squared Mahalanobis distance of the ray to the mean
    if (r > r_use || t <= 0) continue;
    terms.push_back({t, a, c.log_amp - 0.5 * r, r});
    if (r <= r_show && t > o.depth_min && t <= o.depth_max) starts.push_back(t);
  }
  if (starts.empty()) return kEmpty;
  const double min_evidence = o.surface_sigma > 0 ? std::exp(-0.5 * o.surface_sigma * o.surface_sigma) : 0.0;
  double max_log_c = -std::numeric_limits<double>::infinity();
  for (const RayTerm& q : terms) max_log_c = std::max(max_log_c, q.log_c);
  // The climbs in order of their starts. An ascent in 1-D cannot cross a
  // mode, so a start at or beyond a mode already found climbs to that mode
  // or a farther one, never a nearer one: once a surface is found, later
  // starts are not climbed, usually one climb per pixel instead of one per
  // component near the ray. (The mean-shift steps are discrete; on the
  // livingroom frame's full-resolution render the skipped climbs would have
  // moved 90 of 282,412 depths by at most 4.8e-7 m, and no pixel's surface.)
  std::sort(starts.begin(), starts.end());
  double best_t = -1;
  for (double t : starts) {
    if (best_t > 0 && t >= best_t) break;
    bool supported = true;
    for (int it = 0; it < 50; ++it) {  // 1-D mean shift towards a mode of the ray mixture
      double num = 0, den = 0;
      for (const RayTerm& q : terms) {
        const double w = std::exp(q.log_c - max_log_c - 0.5 * q.a * (t - q.t) * (t - q.t)) * q.a;
        num += w * q.t;
        den += w;
      }
      // No density here relative to the ray's strongest term (e.g. the peak
      // of a weight-0 component): not a surface.
      supported = den > 0;
      if (!supported) break;
      const double next = num / den;
      const bool done = std::abs(next - t) < 1e-6;
      t = next;
      if (done) break;
    }
    if (!supported || !(t > o.depth_min && t <= o.depth_max)) continue;
    if (min_evidence > 0 && surface_evidence(terms, t) < min_evidence) continue;  // a graze, not a surface
    if (best_t < 0 || t < best_t) best_t = t;
  }
  return best_t > 0 ? static_cast<float>(best_t) : kEmpty;
}

}  // namespace

void validate(const RenderOptions& o) {
  require(std::isfinite(o.depth_min) && std::isfinite(o.depth_max) && o.depth_min >= 0 && o.depth_min < o.depth_max,
          ErrorCode::InvalidArgument,
          "render: need 0 <= depth_min < depth_max, both finite (got " + std::to_string(o.depth_min) + ", " +
              std::to_string(o.depth_max) + ")");
  require(std::isfinite(o.max_mahalanobis) && o.max_mahalanobis > 0, ErrorCode::InvalidArgument,
          "render: max_mahalanobis must be finite and > 0 (got " + std::to_string(o.max_mahalanobis) + ")");
  require(std::isfinite(o.surface_sigma) && o.surface_sigma >= 0, ErrorCode::InvalidArgument,
          "render: surface_sigma must be finite and >= 0 (got " + std::to_string(o.surface_sigma) + ")");
  require(o.threads >= 0, ErrorCode::InvalidArgument, "render: threads must be >= 0 (got " + std::to_string(o.threads) + ")");
}

std::vector<RayComponent> ray_components(const Gmm& gmm) {
  std::vector<RayComponent> out(gmm.size());
  for (std::size_t m = 0; m < gmm.size(); ++m) {
    const float* s = gmm.covariance(m);
    const float* mu = gmm.mean(m);
    const double a = s[0], b = s[1], c = s[2], d = s[5], e = s[6], f = s[10];
    // Inverse of the symmetric 3x3 [[a b c][b d e][c e f]] by cofactors.
    const double A = d * f - e * e, B = c * e - b * f, C = b * e - c * d;
    const double det = a * A + b * B + c * C;
    require(det > 0 && std::isfinite(det), ErrorCode::Numeric,
            "component " + std::to_string(m) + ": spatial covariance is not positive definite");
    const double D = a * f - c * c, E = b * c - a * e, F = a * d - b * b;
    RayComponent& r = out[m];
    r.p[0] = A / det; r.p[1] = B / det; r.p[2] = C / det;
    r.p[3] = D / det; r.p[4] = E / det; r.p[5] = F / det;
    const double x = mu[0], y = mu[1], z = mu[2];
    r.pm[0] = r.p[0] * x + r.p[1] * y + r.p[2] * z;
    r.pm[1] = r.p[1] * x + r.p[3] * y + r.p[4] * z;
    r.pm[2] = r.p[2] * x + r.p[4] * y + r.p[5] * z;
    r.mpm = x * r.pm[0] + y * r.pm[1] + z * r.pm[2];
    const double w = gmm.weights[m];
    r.log_amp = (w > 0 ? std::log(w) : -std::numeric_limits<double>::infinity()) - 1.5 * std::log(2 * M_PI) -
                0.5 * std::log(det);
  }
  return out;
}

RenderedImages render_expected_surface(const Gmm& gmm, const Camera& camera, const RenderOptions& options,
                                       const ProgressSink& progress) {
  validate(camera);
  validate(options);
  const std::vector<RayComponent> comps = ray_components(gmm);
  RenderedImages r = empty_images(camera);
  // Each pixel tests only the components its tile's rays may meet (exact: render_tiles.hpp).
  const detail::RayTiles tiles = detail::ray_tiles(gmm, camera, shaping_radius2(options));
  const int threads = detail::team_size(options.threads);
  struct Scratch {
    std::vector<RayTerm> terms;
    std::vector<double> starts;
  };
  std::vector<Scratch> scratch(static_cast<std::size_t>(threads));
  const ProgressScope scope(progress);
  detail::progress_begin(Stage::Rendering, static_cast<std::uint64_t>(camera.height));
  // Each pixel depends on its own ray alone: blocks of rows, any team size,
  // the same bits.
  for (int first = 0; first < camera.height; first += kRowsPerBlock) {
    const int rows = std::min(kRowsPerBlock, camera.height - first);
    detail::parallel_for(static_cast<std::size_t>(rows), threads, 1, [&](std::size_t k, int thread) {
      const int v = first + static_cast<int>(k);
      Scratch& s = scratch[static_cast<std::size_t>(thread)];
      for (int u = 0; u < camera.width; ++u) {
        const double d[3] = {(u - camera.cx) / camera.fx, (v - camera.cy) / camera.fy, 1.0};
        r.depth[static_cast<std::size_t>(v) * static_cast<std::size_t>(camera.width) + static_cast<std::size_t>(u)] =
            first_surface(comps, tiles.at(u, v), d, options, s.terms, s.starts);
      }
    });
    detail::progress_at(static_cast<std::uint64_t>(first + rows));
  }
  regress_at_depths(gmm, camera, threads, r);
  detail::progress_event(static_cast<std::uint64_t>(camera.height), 0.0);
  return r;
}

RenderedImages render(const Gmm& gmm, const Camera& camera, const std::array<double, 16>& camera_to_world,
                      const RenderOptions& options, const ProgressSink& progress) {
  const std::string bad = rigid_pose_error(camera_to_world);
  require(bad.empty(), ErrorCode::InvalidArgument, "render: camera_to_world pose: " + bad);
  validate(camera);
  validate(options);
  return render_expected_surface(transform(gmm, inverse_rigid(camera_to_world)), camera, options, progress);
}

RenderedImages render_at_points(const Gmm& gmm, const PointsView& points, const Camera& camera) {
  validate(camera);
  const std::size_t n = points.size;
  std::vector<float> xyz(3 * n), depth(n), gray(n, 0.f), variance(n, 0.f);
  for (std::size_t i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) xyz[3 * i + static_cast<std::size_t>(k)] = points[i][k];
    depth[i] = points[i][2];
  }
  if (n > 0) regress_gray(gmm, xyz.data(), n, gray.data(), variance.data());
  for (float& v : variance) v = std::max(v, 0.f);
  RenderedImages r;
  r.width = camera.width;
  r.height = camera.height;
  r.depth = project_to_image(points, depth.data(), camera, kEmpty);
  r.gray = project_to_image(points, gray.data(), camera, kEmpty);
  r.variance = project_to_image(points, variance.data(), camera, kEmpty);
  return r;
}

}  // namespace sogmm
