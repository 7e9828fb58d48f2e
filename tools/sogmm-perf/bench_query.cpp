// Benchmark of the queries (issue 17): score_samples (4-D) and regress_gray,
// exact against culled (QueryOptions::truncation_nats), on 1 and 2 threads,
// the variants interleaved within each repeat so that machine load hits them
// alike. Also checks the culled answers against the exact ones: the largest
// score deficit against its bound log(1 + M exp(-nats)), and the largest
// change of the regressed gray.
//
// The query points are --points draws from the model itself (seed 1), so
// they lie on its surfaces wherever the model has components, as the points
// of a frame do; with --view C only from its first C components (e.g. the
// first frame's of a sequence map: dense points in one view, as a new frame
// against a map). --room instead of --model builds a synthetic 5 x 5 x 3 m
// room tiled by about 50k flat components (2 cm in the plane, 3 mm across,
// 4.7 cm apart): a map without overlap. Prints one JSON object of medians
// (milliseconds).
//
// Usage: sogmm-bench-query (--model MAP.sogmm | --room) [--points 100000]
//        [--view C] [--repeats 5] [--nats 20]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "sogmm/format.hpp"
#include "sogmm/inference.hpp"
#include "median.hpp"

namespace {

using sogmm::perf::median;

double ms(const std::function<void()>& f) {
  const auto t = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
}

// Six faces of a 5 x 5 x 3 m box tiled by flat components; gray varies
// along each face and correlates a little with position.
sogmm::Gmm tiled_room() {
  const double spacing = 0.047, size[3] = {5, 5, 3};
  sogmm::Gmm g;
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      const int a = (axis + 1) % 3, b = (axis + 2) % 3;
      for (double u = spacing / 2; u < size[a]; u += spacing)
        for (double v = spacing / 2; v < size[b]; v += spacing) {
          float mu[4];
          mu[axis] = static_cast<float>(side * size[axis]);
          mu[a] = static_cast<float>(u);
          mu[b] = static_cast<float>(v);
          mu[3] = static_cast<float>(0.5 + 0.4 * std::sin(7 * u + 3 * v));
          float c[16] = {};
          for (int j = 0; j < 3; ++j) c[5 * j] = 4e-4f;
          c[5 * axis] = 9e-6f;
          c[15] = 1e-3f;
          c[4 * a + 3] = c[12 + a] = 2e-5f;
          g.means.insert(g.means.end(), mu, mu + 4);
          g.covariances.insert(g.covariances.end(), c, c + 16);
          g.weights.push_back(1.0f);
        }
    }
  for (float& w : g.weights) w = 1.0f / static_cast<float>(g.weights.size());
  g.support_size = 1;
  return g;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace sogmm;
  CLI::App app{"sogmm-bench-query: exact and culled score_samples / regress_gray, 1 and 2 threads"};
  std::string path;
  bool room = false;
  std::size_t view = 0;
  std::size_t n = 100000;
  int repeats = 5;
  double nats = 20.0;
  app.add_option("--model", path);
  app.add_flag("--room", room, "synthetic tiled room instead of --model");
  app.add_option("--view", view, "draw the points from the first C components only");
  app.add_option("--points", n);
  app.add_option("--repeats", repeats);
  app.add_option("--nats", nats, "culling cutoff in nats");
  CLI11_PARSE(app, argc, argv);

  if (room == !path.empty()) {
    std::fprintf(stderr, "sogmm-bench-query: give --model FILE or --room\n");
    return 2;
  }
  const Gmm gmm = room ? tiled_room() : format::load(path).gmm;
  const std::size_t m = gmm.size();
  std::vector<float> pts(4 * n), xyz(3 * n);
  Gmm source = gmm;
  if (view > 0 && view < m) {
    source.resize(view);
    double w = 0;
    for (float v : source.weights) w += v;
    for (float& v : source.weights) v = static_cast<float>(v / w);
  }
  sample(source, n, 1, 4, pts.data());
  for (std::size_t i = 0; i < n; ++i)
    for (int j = 0; j < 3; ++j) xyz[3 * i + j] = pts[4 * i + j];

  std::vector<double> exact_score(n), culled_score(n);
  std::vector<float> exact_mean(n), exact_var(n), culled_mean(n), culled_var(n);
  // name -> times; variant: (threads, nats)
  struct Row {
    const char* name;
    int threads;
    double nats;
    bool regress;
    std::vector<double> t;
  };
  std::vector<Row> rows = {{"score_exact_2t", 2, 0, false, {}},   {"score_culled_2t", 2, nats, false, {}},
                           {"regress_exact_2t", 2, 0, true, {}},  {"regress_culled_2t", 2, nats, true, {}},
                           {"score_exact_1t", 1, 0, false, {}},   {"score_culled_1t", 1, nats, false, {}},
                           {"regress_exact_1t", 1, 0, true, {}},  {"regress_culled_1t", 1, nats, true, {}}};
  for (int r = 0; r < repeats; ++r)
    for (Row& row : rows) {
      QueryOptions o;
      o.threads = row.threads;
      o.truncation_nats = row.nats;
      const bool culled = row.nats > 0;
      row.t.push_back(ms([&] {
        if (row.regress)
          regress_gray(gmm, xyz.data(), n, (culled ? culled_mean : exact_mean).data(),
                       (culled ? culled_var : exact_var).data(), o);
        else
          score_samples(gmm, pts.data(), n, 4, (culled ? culled_score : exact_score).data(), o);
      }));
    }
  double score_deficit = 0.0, score_excess = 0.0, mean_change = 0.0, var_change = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    score_deficit = std::max(score_deficit, exact_score[i] - culled_score[i]);
    score_excess = std::max(score_excess, culled_score[i] - exact_score[i]);
    mean_change = std::max(mean_change, static_cast<double>(std::fabs(exact_mean[i] - culled_mean[i])));
    var_change = std::max(var_change, static_cast<double>(std::fabs(exact_var[i] - culled_var[i])));
  }
  std::printf("{\"m\": %zu, \"n\": %zu, \"view\": %zu, \"nats\": %g, \"repeats\": %d", m, n, view, nats, repeats);
  for (const Row& row : rows) std::printf(", \"ms_%s\": %.3f", row.name, median(row.t));
  std::printf(
      ", \"score_speedup_2t\": %.2f, \"regress_speedup_2t\": %.2f, \"score_max_deficit\": %.3g, "
      "\"score_deficit_bound\": %.3g, \"score_max_excess\": %.3g, \"regress_max_mean_change\": %.3g, "
      "\"regress_max_variance_change\": %.3g}\n",
      median(rows[0].t) / median(rows[1].t), median(rows[2].t) / median(rows[3].t), score_deficit,
      std::log1p(static_cast<double>(m) * std::exp(-nats)), score_excess, mean_change, var_change);
  return 0;
}
