// Benchmark of the scale-dependent stages of issue 14 on one real frame:
// the mode count with and without one outlier 1 km away (item 3), and the
// k-means++ seeding against the whole fit (item 6). Prints one JSON object
// with medians over --repeats runs, the outlier/no-outlier ratios of time and
// of neighbour checks (the clock-free cost), and seeding's share of the fit.
//
// Usage: sogmm-bench-scale --depth D --color C --intrinsics J [--decimate 5]
//        [--bandwidth 0.02] [--repeats 7] [--threads 1]
#include <chrono>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>

#include "frame_flags.hpp"
#include "sogmm/camera.hpp"
#include "sogmm/fit.hpp"
#include "sogmm/kmeanspp.hpp"
#include "sogmm/mean_shift.hpp"
#include "median.hpp"

namespace {

template <typename F>
double median_ms(int repeats, F&& f) {
  std::vector<double> ms;
  for (int r = 0; r < repeats; ++r) {
    const auto t = std::chrono::steady_clock::now();
    f();
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count());
  }
  return sogmm::perf::median(std::move(ms));
}

}  // namespace

int main(int argc, char** argv) {
  using namespace sogmm;
  CLI::App app{"sogmm-bench-scale: mode count with a far outlier, k-means++ share of the fit"};
  perf::FrameFlags in;
  in.depth_options.decimate = 5;
  FitOptions fit_options;
  fit_options.em.threads = 1;
  int repeats = 7;
  in.add_to(app);
  app.add_option("--bandwidth", fit_options.bandwidth);
  app.add_option("--repeats", repeats)->check(CLI::Range(1, 1000));
  app.add_option("--threads", fit_options.em.threads);
  CLI11_PARSE(app, argc, argv);

  const PointCloud cloud = in.cloud();
  std::vector<float> with_outlier = cloud.xyzg;
  with_outlier.insert(with_outlier.end(), {0.0f, 0.0f, 1000.0f, 0.5f});  // 1 km down the optical axis
  const std::vector<double> f0 = range_gray_features(cloud.view());
  const std::vector<double> f1 = range_gray_features(PointsView{with_outlier.data(), cloud.size() + 1});

  MeanShiftResult r0, r1;
  const double ms0 = median_ms(repeats, [&] { r0 = mean_shift_flat(f0, fit_options.bandwidth); });
  const double ms1 = median_ms(repeats, [&] { r1 = mean_shift_flat(f1, fit_options.bandwidth); });

  FitResult fit_result;
  const double ms_fit = median_ms(repeats, [&] { fit_result = fit(cloud.view(), fit_options); });
  const double ms_seed = median_ms(repeats, [&] { kmeanspp_seeds(cloud.view(), fit_result.gmm.size(), 0); });

  std::printf(
      "{\"n\": %zu, \"modes\": %zu, \"modes_with_outlier\": %zu, \"ms_mode_count\": %.3f, "
      "\"ms_mode_count_outlier\": %.3f, \"time_ratio\": %.3f, \"checks\": %llu, \"checks_outlier\": %llu, "
      "\"checks_ratio\": %.4f, \"m\": %zu, \"ms_fit\": %.3f, \"ms_seeding\": %.3f, \"seeding_share\": %.4f}\n",
      cloud.size(), r0.size(), r1.size(), ms0, ms1, ms1 / ms0, static_cast<unsigned long long>(r0.neighbour_checks),
      static_cast<unsigned long long>(r1.neighbour_checks),
      static_cast<double>(r1.neighbour_checks) / static_cast<double>(r0.neighbour_checks), fit_result.gmm.size(),
      ms_fit, ms_seed, ms_seed / ms_fit);
  return 0;
}
