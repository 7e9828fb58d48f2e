// The truncated E-step's pair rate against the dense kernel's (issue 35).
// For one frame: the fit's component count M (mode count), its k-means++
// seeds, then EM from those seeds for a fixed number of iterations (tol 0),
// exact and truncated, interleaved `--repeats` times in this process. Prints
// one JSON object with the medians: seconds, evaluated pairs per second
// (N x M x iterations x pair_fraction / EM seconds), the pair fraction, the
// truncated-to-dense ratios of pair rate and of time, and both final
// log-likelihoods. Times are the process's CPU seconds (with --threads 1,
// the E-step's own work even on a machine loaded by other processes, where
// wall time measures the scheduler); "wall_*" gives the wall medians too.
// Same-process ratios are what to compare across builds.
//
// Usage: sogmm-bench-estep --depth D --color C --intrinsics J --decimate d
//        [--bandwidth 0.02] [--nats 20] [--iterations 20] [--repeats 5]
//        [--threads T] [--seed S] [--truncated-only]
// --truncated-only skips the exact runs (for a profile of the truncated
// E-step alone; the ratios are then not printed).
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "frame_flags.hpp"
#include "sogmm/camera.hpp"
#include "sogmm/em.hpp"
#include "sogmm/fit.hpp"
#include "sogmm/kmeanspp.hpp"

namespace {
double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t h = v.size() / 2;
  return v.size() % 2 ? v[h] : 0.5 * (v[h - 1] + v[h]);
}
double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}
}  // namespace

int main(int argc, char** argv) {
  using namespace sogmm;
  CLI::App app{"sogmm-bench-estep: truncated vs dense E-step pair rate"};
  perf::FrameFlags in;
  FitOptions fit_options;
  double nats = 20.0;
  int iterations = 20, repeats = 5;
  in.add_to(app);
  app.add_option("--bandwidth", fit_options.bandwidth);
  app.add_option("--threads", fit_options.em.threads);
  app.add_option("--seed", fit_options.seed);
  app.add_option("--nats", nats, "truncation cutoff of the truncated runs")->check(CLI::PositiveNumber);
  app.add_option("--iterations", iterations, "EM iterations per run (tol 0)")->check(CLI::PositiveNumber);
  app.add_option("--repeats", repeats, "interleaved exact/truncated runs")->check(CLI::PositiveNumber);
  bool truncated_only = false;
  app.add_flag("--truncated-only", truncated_only, "run only the truncated E-step (for profiling)");
  CLI11_PARSE(app, argc, argv);

  const PointCloud cloud = in.cloud();
  FitOptions count_only = fit_options;  // only M is wanted: one EM iteration
  count_only.em.max_iter = 1;
  const FitResult fitted = fit(cloud.view(), count_only);
  const std::size_t n = cloud.size(), m = fitted.gmm.size();
  const std::vector<std::size_t> seeds = kmeanspp_seeds(cloud.view(), m, fit_options.seed);

  struct Runs {
    std::vector<double> seconds, wall, rate, fraction;
    double ll = 0.0;
  } dense, truncated;
  EmOptions em = fit_options.em;
  em.max_iter = iterations;
  em.tol = 0.0;
  const char* kernel = "";
  for (int r = 0; r < repeats; ++r)
    for (Runs* runs : {&dense, &truncated}) {
      if (truncated_only && runs == &dense) continue;
      em.truncation_nats = runs == &dense ? 0.0 : nats;
      EmReport rep;
      const auto t0 = std::chrono::steady_clock::now();
      const double c0 = cpu_seconds();
      fit_em(cloud.view(), seeds, em, &rep);
      const double s = cpu_seconds() - c0;
      runs->wall.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      const double pairs = static_cast<double>(n) * static_cast<double>(m) * rep.iterations * rep.pair_fraction;
      runs->seconds.push_back(s);
      runs->rate.push_back(pairs / s);
      runs->fraction.push_back(rep.pair_fraction);
      runs->ll = rep.log_likelihood;
      kernel = rep.kernel;
    }
  if (truncated_only) {
    std::printf("{\"n\": %zu, \"m\": %zu, \"kernel\": \"%s\", \"s_truncated\": %.4f, \"pairs_per_s_truncated\": %.4g, "
                "\"pair_fraction\": %.4f, \"ll_truncated\": %.6f}\n",
                n, m, kernel, median(truncated.seconds), median(truncated.rate), median(truncated.fraction), truncated.ll);
    return 0;
  }
  const double dense_rate = median(dense.rate), trunc_rate = median(truncated.rate);
  std::printf(
      "{\"n\": %zu, \"m\": %zu, \"kernel\": \"%s\", \"iterations\": %d, \"repeats\": %d, \"nats\": %g, "
      "\"s_dense\": %.4f, \"s_truncated\": %.4f, \"wall_dense\": %.4f, \"wall_truncated\": %.4f, "
      "\"pairs_per_s_dense\": %.4g, \"pairs_per_s_truncated\": %.4g, "
      "\"pair_fraction\": %.4f, \"rate_ratio\": %.3f, \"speedup\": %.3f, \"ll_dense\": %.6f, "
      "\"ll_truncated\": %.6f}\n",
      n, m, kernel, iterations, repeats, nats, median(dense.seconds), median(truncated.seconds), median(dense.wall), median(truncated.wall), dense_rate,
      trunc_rate, median(truncated.fraction), trunc_rate / dense_rate,
      median(dense.seconds) / median(truncated.seconds), dense.ll, truncated.ll);
  return 0;
}
