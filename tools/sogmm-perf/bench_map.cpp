// Benchmark of the map's novelty test (issue 18): 12,288 points (one
// decimated frame) scored against a map of 50,000 components, on 1 and 2
// threads, interleaved in one run. The map is a synthetic room (5 x 5 x 3 m,
// walls, floor and ceiling tiled with flat surface Gaussians: 2 cm in the
// plane, 3 mm across it); the frame is a 2 x 1.5 m patch of one wall drawn
// from the same surface in raster order (as a depth image gives them), so
// every point meets several components (a revisit, the costly case). Also times index building (Map::from_model) and one
// insert_points with novelty on (no fit: the batch is never full).
//
// Prints one JSON object with medians over --repeats runs.
// Usage: sogmm-bench-map [--components 50000] [--points 12288] [--repeats 21]
//
// With --sequence DIR (a Redwood folder: depth/, color/, intrinsics.json,
// trajectory.log) it instead inserts --frames A:B (decimated by --decimate)
// into an append-everything map and a novelty map, then re-inserts the first
// frame at its pose, and prints one JSON line per insert and a summary.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <random>
#include <vector>

#include <CLI/CLI.hpp>

#include "cli_common.hpp"
#include "image_io.hpp"
#include "sequence.hpp"
#include "sogmm/map.hpp"
#include "median.hpp"

namespace {

using sogmm::Pose;

using sogmm::perf::median;

template <typename F>
double median_ms(std::vector<double>& ms, F&& f) {
  const auto t = std::chrono::steady_clock::now();
  f();
  ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count());
  return median(ms);
}


// A point on the room's surface: face f (0..5), coordinates (a, b) in [0, 1).
void surface_point(int face, double a, double b, double p[3], int* normal_axis) {
  const double w = 5.0, d = 5.0, h = 3.0;
  switch (face) {
    case 0: p[0] = 0; p[1] = a * h; p[2] = b * d; *normal_axis = 0; break;
    case 1: p[0] = w; p[1] = a * h; p[2] = b * d; *normal_axis = 0; break;
    case 2: p[0] = a * w; p[1] = 0; p[2] = b * d; *normal_axis = 1; break;
    case 3: p[0] = a * w; p[1] = h; p[2] = b * d; *normal_axis = 1; break;
    case 4: p[0] = a * w; p[1] = b * h; p[2] = 0; *normal_axis = 2; break;
    default: p[0] = a * w; p[1] = b * h; p[2] = d; *normal_axis = 2; break;
  }
}

sogmm::Model room_map(std::size_t m, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  sogmm::Model model;
  model.gmm.resize(m);
  // Faces weighted by area: 2 x (5x3) walls x, 2 x (5x5) floor/ceiling, 2 x (5x3) walls z.
  const double area[6] = {15, 15, 25, 25, 15, 15};
  std::discrete_distribution<int> face(area, area + 6);
  for (std::size_t k = 0; k < m; ++k) {
    double p[3];
    int n = 0;
    surface_point(face(rng), u(rng), u(rng), p, &n);
    model.gmm.weights[k] = 1.0f / static_cast<float>(m);
    for (int i = 0; i < 3; ++i) model.gmm.means[4 * k + i] = static_cast<float>(p[i]);
    model.gmm.means[4 * k + 3] = static_cast<float>(u(rng));
    float* c = model.gmm.covariances.data() + 16 * k;
    std::fill(c, c + 16, 0.0f);
    for (int i = 0; i < 3; ++i) c[5 * i] = i == n ? 9e-6f : 4e-4f;
    c[15] = 0.01f;
  }
  model.gmm.support_size = 100 * m;
  model.key_values.emplace_back(sogmm::kCoordinateFrameKey, "world");
  return model;
}

void print_frame(const char* map, const sogmm::FrameStats& f) {
  std::printf(
      "{\"map\": \"%s\", \"frame\": %llu, \"points\": %zu, \"novel\": %zu, \"components\": %zu, "
      "\"ms_novelty\": %.2f, \"ms_fit\": %.1f, \"ms_merge\": %.2f}\n",
      map, static_cast<unsigned long long>(f.index), f.n_points, f.n_novel, f.n_components, f.ms_novelty, f.ms_fit,
      f.ms_merge);
}

int run_sequence(const std::string& dir, const std::string& range, int decimate) {
  namespace tools = sogmm::tools;
  const auto frames = tools::list_sequence(dir);
  const auto poses = tools::read_trajectory(dir + "/trajectory.log");
  const auto selected = tools::parse_frame_range(range, frames.size());
  const sogmm::Camera camera = sogmm::read_intrinsics_json(dir + "/intrinsics.json");
  sogmm::MapOptions append_options, novelty_options;
  append_options.novelty = false;
  append_options.depth.decimate = novelty_options.depth.decimate = decimate;
  append_options.fit.em.threads = novelty_options.fit.em.threads = 2;
  sogmm::Map append(append_options), novelty(novelty_options);
  for (std::size_t i : selected) {
    const tools::LoadedFrame f = tools::load_frame(frames[i].depth, frames[i].color);
    print_frame("append", append.insert_rgbd(f.view(camera), poses[i]));
    print_frame("novelty", novelty.insert_rgbd(f.view(camera), poses[i]));
  }
  novelty.flush();
  const std::size_t before = novelty.size();
  const tools::LoadedFrame f0 = tools::load_frame(frames[selected[0]].depth, frames[selected[0]].color);
  {
    // Where the first frame's points score against the map that holds them:
    // percentiles of the local 3-D log-likelihood (the novelty threshold's scale).
    const sogmm::PointCloud cloud = sogmm::backproject(f0.view(camera), novelty_options.depth);
    const sogmm::Pose& p = poses[selected[0]];
    std::vector<double> xyz(3 * cloud.size()), ll(cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i)
      for (int r = 0; r < 3; ++r)
        xyz[3 * i + r] = p[4 * r] * cloud.xyzg[4 * i] + p[4 * r + 1] * cloud.xyzg[4 * i + 1] +
                         p[4 * r + 2] * cloud.xyzg[4 * i + 2] + p[4 * r + 3];
    novelty.local_log_likelihood(xyz.data(), cloud.size(), ll.data());
    std::sort(ll.begin(), ll.end());
    std::printf("{\"first_frame_local_loglik_percentiles\": {");
    const int q[] = {1, 5, 10, 25, 50, 75, 90};
    for (int k = 0; k < 7; ++k)
      std::printf("%s\"p%d\": %.2f", k ? ", " : "", q[k], ll[ll.size() * q[k] / 100]);
    std::printf("}}\n");
  }
  const sogmm::FrameStats again = novelty.insert_rgbd(f0.view(camera), poses[selected[0]]);
  print_frame("novelty-reinsert-first", again);
  novelty.flush();
  std::printf("{\"append_components\": %zu, \"novelty_components\": %zu, \"ratio\": %.3f, "
              "\"reinsert_novel\": %zu, \"reinsert_points\": %zu, \"reinsert_added_components\": %zu}\n",
              append.size(), before, static_cast<double>(before) / static_cast<double>(append.size()),
              again.n_novel, again.n_points, novelty.size() - before);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Benchmark of the map's novelty test (issue 18)"};
  std::size_t components = 50000, points = 12288;
  int repeats = 21;
  app.add_option("--components", components, "map components")->check(CLI::Range(1, 10000000));
  app.add_option("--points", points, "frame points")->check(CLI::Range(1, 10000000));
  app.add_option("--repeats", repeats, "timed runs per variant")->check(CLI::Range(1, 1000));
  std::string sequence, range = "0:3";
  int decimate = 5;
  app.add_option("--sequence", sequence, "Redwood folder: real-frame growth instead of the synthetic benchmark");
  app.add_option("--frames", range, "frames of --sequence, A:B");
  app.add_option("--decimate", decimate, "decimation of --sequence frames")->check(CLI::Range(1, 64));
  CLI11_PARSE(app, argc, argv);
  if (!sequence.empty()) return sogmm::tools::run_guarded([&] { return run_sequence(sequence, range, decimate); });

  std::mt19937_64 rng(18);
  const sogmm::Model model = room_map(components, rng);
  std::vector<double> build_ms;
  sogmm::MapOptions o;
  o.batch_size = sogmm::kMaxPoints;  // never fit: time the novelty test alone
  sogmm::Map map1, map2;
  for (int r = 0; r < 3; ++r)
    median_ms(build_ms, [&] {
      o.fit.em.threads = 1;
      map1 = sogmm::Map::from_model(model, o);
    });
  o.fit.em.threads = 2;
  map2 = sogmm::Map::from_model(model, o);

  // The frame: a 2 x 1.5 m patch of wall x = 0 seen from inside, in the camera
  // frame of a camera at (2.5, 1.5, 2.5) looking along -x.
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.003);
  std::vector<float> cam(4 * points);
  std::vector<double> world(3 * points);
  const Pose pose = {0, 0, -1, 2.5, 0, 1, 0, 1.5, 1, 0, 0, 2.5, 0, 0, 0, 1};  // camera z -> world -x
  // Row by row as a depth image gives them (128 columns; rows as needed).
  const std::size_t cols = 128, rows = (points + cols - 1) / cols;
  for (std::size_t i = 0; i < points; ++i) {
    const double col = static_cast<double>(i % cols) + u(rng) - 0.5, row = static_cast<double>(i / cols) + u(rng) - 0.5;
    const double wx = noise(rng), wy = 0.75 + 1.5 * row / static_cast<double>(rows),
                 wz = 1.5 + 2.0 * col / static_cast<double>(cols);
    world[3 * i] = wx;
    world[3 * i + 1] = wy;
    world[3 * i + 2] = wz;
    // Camera coordinates: R^T (w - t).
    const double d[3] = {wx - pose[3], wy - pose[7], wz - pose[11]};
    for (int r = 0; r < 3; ++r)
      cam[4 * i + r] = static_cast<float>(pose[r] * d[0] + pose[4 + r] * d[1] + pose[8 + r] * d[2]);
    cam[4 * i + 3] = 0.5f;
  }
  std::vector<double> ll(points);
  std::vector<double> t1, t2, ins, cpu1;
  for (int r = 0; r < repeats; ++r) {  // interleaved: load changes hit both alike
    // Process CPU time of the one-thread run: what it costs on an idle core
    // (the shared machine's load stretches wall time, not CPU time).
    const std::clock_t c0 = std::clock();
    median_ms(t1, [&] { map1.local_log_likelihood(world.data(), points, ll.data()); });
    cpu1.push_back(1000.0 * static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC);
    median_ms(t2, [&] { map2.local_log_likelihood(world.data(), points, ll.data()); });
  }
  std::size_t novel = 0;
  for (double v : ll) novel += v < o.novelty_threshold ? 1 : 0;
  double candidates = 0;
  std::vector<std::uint32_t> ids;
  for (std::size_t i = 0; i < points; ++i) {
    map2.index().query_point(world.data() + 3 * i, ids);
    candidates += static_cast<double>(ids.size());
  }
  for (int r = 0; r < std::min(repeats, 5); ++r) {
    sogmm::Map fresh = sogmm::Map::from_model(model, o);
    median_ms(ins, [&] { fresh.insert_points(sogmm::PointsView{cam.data(), points}, pose); });
  }
  const double m1 = median(t1), m2 = median(t2);
  std::printf(
      "{\"components\": %zu, \"points\": %zu, \"repeats\": %d, \"novelty_cpu_ms_1_thread\": %.3f, "
      "\"novelty_ms_1_thread\": %.3f, "
      "\"novelty_ms_2_threads\": %.3f, \"speedup_2_over_1\": %.2f, \"insert_ms_2_threads\": %.3f, "
      "\"index_build_ms\": %.2f, \"cell_size_m\": %.4f, \"mean_candidates_per_point\": %.2f, "
      "\"novel_points\": %zu}\n",
      components, points, repeats, median(cpu1), m1, m2, m1 / m2, median(ins), median(build_ms), map2.index().cell_size(),
      candidates / static_cast<double>(points), novel);
  return 0;
}
