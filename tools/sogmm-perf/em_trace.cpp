// EM convergence on quantised depth (issue 14 item 10). For one frame:
// 1. the mean log-likelihood of every EM iteration (tol 0) and, after given
//    iteration counts, how many components have their smallest covariance
//    eigenvalue at the reg_covar floor and along which axis it points;
// 2. plain EM and EM with the depth-bin floor (DepthQuantisation), each with
//    the default tol and max_iter: iterations, converged, mean log-likelihood
//    of the fitted points, and of a held-out copy of the frame whose points
//    are moved along their rays uniformly within their depth bins (what the
//    sensor saw before it quantised).
//
// Usage: sogmm-em-trace --depth D --color C --intrinsics J --decimate 2
//        --bandwidth 0.02 --seed S [--trace-iter 150] [--at 50,100,130]
//        [--dequantise] [--dither] [--dump-points FILE]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include <CLI/CLI.hpp>
#include <Eigen/Eigenvalues>

#include "frame_flags.hpp"
#include "sogmm/camera.hpp"
#include "sogmm/depth_quantisation.hpp"
#include "sogmm/em.hpp"
#include "sogmm/inference.hpp"
#include "sogmm/kmeanspp.hpp"
#include "sogmm/mean_shift.hpp"

namespace {
using namespace sogmm;

// Each point moved along its ray to a uniform depth within the bin of its
// level (half way to the neighbouring levels).
PointCloud dithered(const PointCloud& cloud, std::uint64_t seed) {
  std::vector<double> levels;
  for (std::size_t i = 0; i < cloud.size(); ++i) levels.push_back(cloud.xyzg[4 * i + 2]);
  std::sort(levels.begin(), levels.end());
  levels.erase(std::unique(levels.begin(), levels.end()), levels.end());
  PointCloud out = cloud;
  if (levels.size() < 2) return out;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  for (std::size_t i = 0; i < out.size(); ++i) {
    float* q = &out.xyzg[4 * i];
    const std::size_t j = static_cast<std::size_t>(std::lower_bound(levels.begin(), levels.end(), q[2]) - levels.begin());
    const double lo = j > 0 ? levels[j - 1] : 2.0 * levels[j] - levels[j + 1];
    const double hi = j + 1 < levels.size() ? levels[j + 1] : 2.0 * levels[j] - levels[j - 1];
    const double s = (q[2] + u(rng) * (hi - lo) / 2.0) / q[2];
    for (int k = 0; k < 3; ++k) q[k] = static_cast<float>(q[k] * s);
  }
  return out;
}
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"sogmm-em-trace: EM on quantised depth"};
  sogmm::perf::FrameFlags in;
  std::string dump, at = "50,100,130";
  double bandwidth = 0.02;
  std::uint64_t seed = 0;
  EmOptions em;
  int trace_iter = 150;
  bool dither = false, dequantise = false;
  in.add_to(app);
  app.add_option("--bandwidth", bandwidth);
  app.add_option("--seed", seed);
  app.add_option("--trace-iter", trace_iter, "iterations of the traced EM (0: no trace)");
  double reg_covar = 1e-6;  // explicit: the floor the trace counts components at
  app.add_option("--reg-covar", reg_covar);
  app.add_option("--at", at, "iteration counts at which to count components at the floor");
  app.add_flag("--dequantise", dequantise, "trace EM with the depth-bin floor along the rays");
  app.add_flag("--dither", dither, "fit the dithered frame instead of the quantised one");
  app.add_option("--dump-points", dump, "write N, M (uint64), N x 4 float32 points, M seed indices (uint64)");
  CLI11_PARSE(app, argc, argv);
  em.reg_covar = reg_covar;

  const PointCloud quantised = in.cloud();
  const PointCloud held_out = dithered(quantised, seed + 1000);
  const PointCloud cloud = dither ? dithered(quantised, seed + 2000) : quantised;
  const MeanShiftResult modes = mean_shift_flat(range_gray_features(cloud.view()), bandwidth, MeanShiftOptions{});
  const std::size_t m = modes.size();
  const std::vector<std::size_t> seeds = kmeanspp_seeds(cloud.view(), m, seed);
  const DepthQuantisation q = DepthQuantisation::detect(cloud.view());
  std::printf("N %zu M %zu, depth quantised: %s\n", cloud.size(), m, q.empty() ? "no" : "yes");
  if (!dump.empty()) {
    std::ofstream out(dump, std::ios::binary);
    const std::uint64_t header[2] = {cloud.size(), m};
    out.write(reinterpret_cast<const char*>(header), sizeof header);
    out.write(reinterpret_cast<const char*>(cloud.xyzg.data()), cloud.xyzg.size() * sizeof(float));
    for (std::size_t s : seeds) {
      const std::uint64_t v = s;
      out.write(reinterpret_cast<const char*>(&v), sizeof v);
    }
  }
  if (trace_iter > 0) {
    EmOptions t = em;
    t.tol = 0.0;
    t.max_iter = trace_iter;
    if (dequantise) t.quantisation = q;
    double prev = 0.0;
    fit_em(cloud.view(), seeds, t, nullptr, [&](int it, double ll) {
      std::printf("iter %d ll %.7f delta %.7f\n", it, ll, ll - prev);
      prev = ll;
    });
    std::stringstream ss(at);
    for (std::string item; std::getline(ss, item, ',');) {
      t.max_iter = std::stoi(item);
      const Gmm g = fit_em(cloud.view(), seeds, t);
      int at_floor[4] = {0, 0, 0, 0}, total = 0;
      for (std::size_t k = 0; k < g.size(); ++k) {
        Eigen::Matrix4d c;
        for (int i = 0; i < 16; ++i) c(i / 4, i % 4) = g.covariances[16 * k + i];
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> es(c);
        if (es.eigenvalues()(0) < 1.5 * reg_covar) {
          ++total;
          int axis;
          es.eigenvectors().col(0).cwiseAbs().maxCoeff(&axis);
          ++at_floor[axis];
        }
      }
      std::printf("after %d iterations: %d of %zu components with smallest eigenvalue < 1.5 reg_covar "
                  "(mostly along x %d, y %d, z %d, gray %d)\n",
                  t.max_iter, total, g.size(), at_floor[0], at_floor[1], at_floor[2], at_floor[3]);
    }
  }
  for (int dq = 0; dq < 2; ++dq) {
    EmOptions t = em;
    if (dq) t.quantisation = q;
    EmReport rep;
    const Gmm g = fit_em(cloud.view(), seeds, t, &rep);
    std::printf("%s EM: %d iterations, converged %d, LL fitted points %.5f, LL held-out dithered frame %.5f\n",
                dq ? "floored" : "plain", rep.iterations, rep.converged ? 1 : 0, rep.log_likelihood,
                mean_log_likelihood(g, held_out.xyzg.data(), held_out.size(), 4));
  }
  return 0;
}
