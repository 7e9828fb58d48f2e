// Occupancy of a SOGMM map against OctoMap, GMMap-style (issue 31): both
// built from the same frames of a Redwood sequence with the same poses, both
// asked about the rays of another frame on its decimated pixel grid:
// occupied = the observed depth; free = 20%, 50% and 80% of it and 5 cm in
// front of it; points behind the surface are not scored. Prints, per model,
// the ROC AUC, the file size (the SOGMM map file; OctoMap's .bt, its
// maximum-likelihood binary tree), the build time and the query throughput
// (medians of --repeats; the SOGMM map's renders kept, as between two
// inserts; OctoMap's search on the same thread count).
//
// Usage: sogmm-occupancy-octomap --sequence DIR [--map-frames 0:2] [--ray-frames 2]
//          [--decimate 5] [--octomap-decimate 1] [--resolutions 0.02,0.05] [--threads 2] [--repeats 3]
//          [--save-map FILE] [--map FILE] [--compare-main] [--write-answers FILE]
// --write-answers writes the scored points and this build's answers for a
// byte-for-byte comparison with another build's: n float32 xyz triples,
// then n float64 probabilities, then n uint8 states (little-endian, raw).
// --map answers with a map saved by an earlier run's --save-map (no build;
// the loop's map takes minutes); --resolutions none skips OctoMap.
// Frame selections as `sogmm map --frames`: I, A:B or A:B:STEP. The synthetic
// loop of the issue: `sogmm demo --write-frame DIR --loop`, then
// --map-frames 0:300:3 --ray-frames 1:300:30.
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <ctime>
#include <numeric>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#ifdef SOGMM_HAVE_OCTOMAP
#include <octomap/octomap.h>
#endif

#include "image_io.hpp"
#include "sequence.hpp"
#include "sogmm/format.hpp"
#include "sogmm/map.hpp"
#include "occupancy_main_path.hpp"
#include "surface_distance_main_path.hpp"
#include "sogmm/occupancy.hpp"
#include "sogmm/surface_distance.hpp"

namespace {

using sogmm::Pose;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

double process_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// The median wall time of `repeats` calls; `cpu` (if given) receives the
// median CPU time of all threads per call, which other sessions' load on a
// shared machine inflates far less than the wall time.
template <typename F>
double median_seconds(int repeats, F&& f, double* cpu = nullptr) {
  std::vector<double> s, c;
  for (int r = 0; r < repeats; ++r) {
    const auto t = Clock::now();
    const double c0 = process_cpu_seconds();
    f();
    c.push_back(process_cpu_seconds() - c0);
    s.push_back(seconds_since(t));
  }
  std::sort(s.begin(), s.end());
  std::sort(c.begin(), c.end());
  if (cpu != nullptr) *cpu = c[c.size() / 2];
  return s[s.size() / 2];
}

// ROC AUC by ranks (ties share their mean rank): the probability that a
// random occupied point scores above a random free one.
double roc_auc(const std::vector<double>& score, const std::vector<int>& label) {
  std::vector<std::size_t> order(score.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return score[a] < score[b]; });
  double rank_sum = 0, positives = 0;
  for (std::size_t i = 0; i < order.size();) {
    std::size_t j = i;
    while (j < order.size() && score[order[j]] == score[order[i]]) ++j;
    const double mean_rank = 0.5 * static_cast<double>(i + 1 + j);
    for (std::size_t k = i; k < j; ++k)
      if (label[order[k]]) {
        rank_sum += mean_rank;
        ++positives;
      }
    i = j;
  }
  const double negatives = static_cast<double>(score.size()) - positives;
  return (rank_sum - positives * (positives + 1) / 2) / (positives * negatives);
}

void to_world(const Pose& p, const double c[3], float out[3]) {
  for (int i = 0; i < 3; ++i)
    out[i] = static_cast<float>(p[4 * i] * c[0] + p[4 * i + 1] * c[1] + p[4 * i + 2] * c[2] + p[4 * i + 3]);
}

// The scored points of one frame: its valid pixels on the decimated grid
// at the observed depth (label 1) and at 20/50/80% of it and 5 cm before it
// (label 0), in the world frame.
void ray_points(const sogmm::tools::LoadedFrame& f, const sogmm::Camera& cam, const sogmm::DepthOptions& depth,
                int step, const Pose& pose, std::vector<float>& xyz, std::vector<int>& label) {
  for (int v = 0; v < f.height; v += step)
    for (int u = 0; u < f.width; u += step) {
      const double z = f.depth[static_cast<std::size_t>(v) * f.width + u] / depth.depth_scale;
      if (!(z > depth.depth_min && z <= depth.depth_max)) continue;
      const double ray[3] = {(u - cam.cx) / cam.fx, (v - cam.cy) / cam.fy, 1.0};
      const double len = std::sqrt(ray[0] * ray[0] + ray[1] * ray[1] + 1.0);
      const double along[5] = {z, 0.2 * z, 0.5 * z, 0.8 * z, z - 0.05 / len};
      for (int k = 0; k < 5; ++k) {
        const double c[3] = {ray[0] * along[k], ray[1] * along[k], along[k]};
        float w[3];
        to_world(pose, c, w);
        xyz.insert(xyz.end(), w, w + 3);
        label.push_back(k == 0 ? 1 : 0);
      }
    }
}

void report(const char* name, double auc, std::size_t bytes, double build_s, std::size_t n, double query_s) {
  std::printf("%-22s AUC %.4f  file %9zu bytes  build %7.3f s  query %6.2f M points/s\n", name, auc, bytes, build_s,
              static_cast<double>(n) / query_s / 1e6);
  std::printf("{\"model\": \"%s\", \"auc\": %.6f, \"bytes\": %zu, \"build_s\": %.4f, \"points_per_s\": %.1f}\n", name,
              auc, bytes, build_s, static_cast<double>(n) / query_s);
}

// Surface distance on the same points: this build, and with `compare_main`
// main's block scan (d33d204) timed in the same run and compared bitwise
// (distances and gradients; timed without gradients).
void distance_rows(const sogmm::Map& map, const std::vector<float>& xyz, int threads, int repeats, bool compare_main) {
  const std::size_t n = xyz.size() / 3;
  std::vector<double> dist(n), dist_main(n), grad(3 * n), grad_main(3 * n);
  double cpu = 0.0, main_cpu = 0.0;
  const double query = median_seconds(
      repeats, [&] { sogmm::surface_distance(map, xyz.data(), n, dist.data(), nullptr, {}, threads); }, &cpu);
  if (!compare_main) {
    std::printf("surface distance: %.3f M points/s (%.3f M points per CPU second; %zu components, %d threads)\n",
                n / query * 1e-6, n / cpu * 1e-6, map.size(), threads);
    return;
  }
  const sogmm::Gmm& gmm = map.model().gmm;
  const double main_query = median_seconds(
      repeats, [&] { sogmm_bench::main_surface_distance(gmm, xyz.data(), n, dist_main.data(), nullptr, threads); },
      &main_cpu);
  sogmm::surface_distance(map, xyz.data(), n, dist.data(), grad.data(), {}, threads);
  sogmm_bench::main_surface_distance(gmm, xyz.data(), n, dist_main.data(), grad_main.data(), threads);
  std::size_t differ = 0;
  for (std::size_t i = 0; i < n; ++i)
    differ += dist[i] != dist_main[i] || grad[3 * i] != grad_main[3 * i] || grad[3 * i + 1] != grad_main[3 * i + 1] ||
              grad[3 * i + 2] != grad_main[3 * i + 2];
  std::printf("surface distance: main (d33d204) %.3f M points/s, this build %.3f M points/s, ratio %.2f; "
              "per CPU second %.3f and %.3f M points, ratio %.2f; "
              "points whose distance or gradient differs bitwise %zu of %zu (%zu components, %d threads)\n",
              n / main_query * 1e-6, n / query * 1e-6, main_query / query, n / main_cpu * 1e-6, n / cpu * 1e-6,
              main_cpu / cpu, differ, n, map.size(), threads);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Occupancy of a SOGMM map against OctoMap on the rays of a held-out frame"};
  std::string dir, map_frames = "0:2", ray_frames = "2", resolutions = "0.02,0.05", save_map, load_map, answers;
  int decimate = 5, octomap_decimate = 1, threads = 2, repeats = 3;
  bool compare_main = false, distance_only = false, cold = false;
  app.add_option("--sequence", dir, "Redwood folder: depth/, color/, intrinsics.json, trajectory.log")->required();
  app.add_option("--map-frames", map_frames, "frames the maps are built from (I, A:B or A:B:STEP)")
      ->capture_default_str();
  app.add_option("--ray-frames", ray_frames, "frames whose rays are scored (I, A:B or A:B:STEP)")->capture_default_str();
  app.add_option("--decimate", decimate, "SOGMM map decimation and the scored pixel grid")->capture_default_str();
  app.add_option("--octomap-decimate", octomap_decimate, "pixels OctoMap inserts (1 = every pixel)")
      ->capture_default_str();
  app.add_option("--resolutions", resolutions, "OctoMap resolutions (m, comma-separated)")->capture_default_str();
  app.add_option("--threads", threads, "query threads")->capture_default_str();
  app.add_option("--repeats", repeats, "timed repeats (median)")->capture_default_str();
  app.add_option("--save-map", save_map, "write the SOGMM map built from --map-frames here");
  app.add_option("--map", load_map, "answer with this saved map instead of building one (build time 0)");
  app.add_option("--write-answers", answers,
                 "write the points (n x 3 float32), then this build's probabilities (n float64) and states (n uint8)");
  app.add_flag("--compare-main", compare_main,
               "also time main's occupancy (a67de64: erfc, per-point projections) and block-scan surface distance "
               "(d33d204) on the "
               "same points, and report how far the answers are from them");
  app.add_flag("--cold", cold,
               "also time one first call on a freshly loaded map (renders every frame it needs; with "
               "--compare-main main's too): minutes on the loop map");
  app.add_flag("--distance-only", distance_only,
               "time surface distance alone (with --compare-main: against main's); no occupancy, no OctoMap");
  CLI11_PARSE(app, argc, argv);
  try {
    using namespace sogmm;
    const auto frames = tools::list_sequence(dir);
    std::vector<std::size_t> selected = tools::parse_frame_range(map_frames, frames.size());
    const std::size_t n_map = selected.size();
    for (std::size_t f : tools::parse_frame_range(ray_frames, frames.size())) selected.push_back(f);
    const std::string traj_path = dir + "/trajectory.log";
    const std::vector<Pose> poses =
        tools::poses_of_frames(tools::read_trajectory_log(traj_path), traj_path, frames, selected, false);
    const Camera cam = read_intrinsics_json(dir + "/intrinsics.json");
    const auto frame = [&](std::size_t k) { return tools::load_frame(frames[selected[k]].depth, frames[selected[k]].color); };

    MapOptions mo;
    mo.depth.decimate = decimate;
    mo.fit.em.threads = threads;
    std::vector<float> xyz;
    std::vector<int> label;
    for (std::size_t k = n_map; k < selected.size(); ++k) ray_points(frame(k), cam, mo.depth, decimate, poses[k], xyz, label);
    const std::size_t n = label.size();
    std::printf("sequence %s: maps from frames %s (%zu), the rays of frames %s (%zu) at d = %d: %zu points (%zu occupied)\n",
                dir.c_str(), map_frames.c_str(), n_map, ray_frames.c_str(), selected.size() - n_map, decimate, n,
                static_cast<std::size_t>(std::count(label.begin(), label.end(), 1)));

    auto t0 = Clock::now();
    Map map(mo);
    if (!load_map.empty()) {
      map = Map::from_model(format::load(load_map), mo);
    } else {
      for (std::size_t k = 0; k < n_map; ++k) map.insert_rgbd(frame(k).view(cam), poses[k]);
      map.flush();
    }
    const double map_build = load_map.empty() ? seconds_since(t0) : 0.0;
    if (!save_map.empty()) format::save(save_map, map.to_model());
    if (distance_only) {
      distance_rows(map, xyz, threads, repeats, compare_main);
      return 0;
    }
    const std::size_t map_bytes = format::to_bytes(map.to_model()).size();
    std::vector<double> p(n);
    const Model saved = map.to_model();
    if (cold) {
      Map fresh = Map::from_model(saved, mo);
      const double s = median_seconds(1, [&] { occupancy(fresh, xyz.data(), n, p.data(), nullptr, {}, threads); });
      std::printf("occupancy, first call (renders): this build %.1f s, %.4f M points/s\n", s, n / s * 1e-6);
      if (compare_main) {
        std::vector<std::uint8_t> sm(n);
        Map again = Map::from_model(saved, mo);
        const double sm_s = median_seconds(
            1, [&] { sogmm_bench::main_occupancy(again, xyz.data(), n, p.data(), sm.data(), threads); });
        std::printf("occupancy, first call (renders): main (a67de64) %.1f s, %.4f M points/s, ratio %.2f\n", sm_s,
                    n / sm_s * 1e-6, sm_s / s);
      }
    }
    occupancy(map, xyz.data(), n, p.data(), nullptr, {}, threads);  // renders, kept until the map changes
    double map_cpu = 0.0;
    const double map_query =
        median_seconds(repeats, [&] { occupancy(map, xyz.data(), n, p.data(), nullptr, {}, threads); }, &map_cpu);
    char name[64];
    std::snprintf(name, sizeof name, "SOGMM map (%zu comp.)", map.size());
    report(name, roc_auc(p, label), map_bytes, map_build, n, map_query);
    std::printf("occupancy: %.3f M points per CPU second (median CPU %.4f s per call, all threads; %d threads)\n",
                n / map_cpu * 1e-6, map_cpu, threads);
    if (!answers.empty()) {
      std::vector<std::uint8_t> s(n);
      occupancy(map, xyz.data(), n, p.data(), s.data(), {}, threads);
      std::ofstream out(answers, std::ios::binary);
      out.write(reinterpret_cast<const char*>(xyz.data()), static_cast<std::streamsize>(xyz.size() * sizeof(float)));
      out.write(reinterpret_cast<const char*>(p.data()), static_cast<std::streamsize>(n * sizeof(double)));
      out.write(reinterpret_cast<const char*>(s.data()), static_cast<std::streamsize>(n));
      if (!out) throw std::runtime_error("cannot write " + answers);
    }
    if (compare_main) {
      std::vector<double> pm(n);
      std::vector<std::uint8_t> sm(n), s(n);
      occupancy(map, xyz.data(), n, p.data(), s.data(), {}, threads);
      const double main_query =
          median_seconds(repeats, [&] { sogmm_bench::main_occupancy(map, xyz.data(), n, pm.data(), sm.data(), threads); });
      double worst = 0.0;
      std::size_t states = 0;
      for (std::size_t i = 0; i < n; ++i) {
        worst = std::max(worst, std::abs(p[i] - pm[i]));
        states += s[i] != sm[i];
      }
      std::printf("occupancy, renders kept: main (a67de64) %.3f M points/s, this build %.3f M points/s, ratio %.2f "
                  "(%d threads); largest |p - p_main| %.3g, states that differ %zu of %zu\n",
                  n / main_query * 1e-6, n / map_query * 1e-6, main_query / map_query, threads, worst, states, n);
    }
    distance_rows(map, xyz, threads, repeats, compare_main);

#ifdef SOGMM_HAVE_OCTOMAP
    std::stringstream res_list(resolutions == "none" ? std::string() : resolutions);
    for (std::string item; std::getline(res_list, item, ',');) {
      const double res = std::stod(item);
      t0 = Clock::now();
      octomap::OcTree tree(res);
      for (std::size_t k = 0; k < n_map; ++k) {
        DepthOptions od = mo.depth;
        od.decimate = octomap_decimate;
        const PointCloud cloud = backproject(frame(k).view(cam), od);
        octomap::Pointcloud scan;
        for (std::size_t i = 0; i < cloud.size(); ++i) {
          const double c[3] = {cloud.xyzg[4 * i], cloud.xyzg[4 * i + 1], cloud.xyzg[4 * i + 2]};
          float w[3];
          to_world(poses[k], c, w);
          scan.push_back(w[0], w[1], w[2]);
        }
        const octomap::point3d origin(static_cast<float>(poses[k][3]), static_cast<float>(poses[k][7]),
                                      static_cast<float>(poses[k][11]));
        tree.insertPointCloud(scan, origin);
      }
      tree.updateInnerOccupancy();
      tree.prune();
      const double build = seconds_since(t0);
      std::stringstream bt;
      tree.writeBinary(bt);
      std::vector<double> q(n);
      auto ask = [&] {
#pragma omp parallel for num_threads(threads) schedule(static)
        for (std::size_t i = 0; i < n; ++i) {
          const octomap::OcTreeNode* node = tree.search(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
          q[i] = node ? node->getOccupancy() : 0.5;
        }
      };
      ask();
      const double query = median_seconds(repeats, ask);
      std::snprintf(name, sizeof name, "OctoMap %.3g m (.bt)", res);
      report(name, roc_auc(q, label), bt.str().size(), build, n, query);
    }
#else
    std::printf("OctoMap: not built (liboctomap-dev missing); only the SOGMM row\n");
#endif
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sogmm-occupancy-octomap: error: %s\n", e.what());
    return 1;
  }
}
