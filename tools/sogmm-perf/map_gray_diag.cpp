// Diagnosis of the map's PSNR loss (issue 18): where does the gray error of
// the map's rendering of one frame come from, compared with that frame's own
// fit? Builds the map of a posed sequence as `sogmm map` does (same options),
// recording for frame --frame the 3-D novelty score of each of its points
// when it was inserted and which rule decided it (explained: score >=
// threshold; pending: below it but near a pending point; novel). After the
// final flush it regresses gray at that frame's points from the map and from
// the frame's own fit (novelty off, that frame alone, as `sogmm fit
// --sequence --frames K`) and splits the squared-error difference by class.
// The pending rule is replayed here (1 cm voxels and their 26 neighbours,
// cleared at each flush) and checked against the map's novel counts.
//
// Usage: sogmm-map-gray-diag DIR --trajectory LOG [--frames A:B] --frame K
//          [--decimate 5] [--bandwidth 0.02] [--threshold 3]
// Prints a table and one JSON line.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <tuple>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "cli_common.hpp"
#include "image_io.hpp"
#include "map_run.hpp"
#include "sequence.hpp"
#include "sogmm/error.hpp"
#include "sogmm/inference.hpp"
#include "sogmm/map.hpp"
#include "sogmm/metrics.hpp"

namespace {
using namespace sogmm;
using Voxel = std::tuple<long long, long long, long long>;

Voxel voxel_of(const double* x) {
  return {static_cast<long long>(std::floor(x[0] / 0.01)), static_cast<long long>(std::floor(x[1] / 0.01)),
          static_cast<long long>(std::floor(x[2] / 0.01))};
}
bool near(const std::set<Voxel>& s, const Voxel& v) {
  for (long long a = -1; a <= 1; ++a)
    for (long long b = -1; b <= 1; ++b)
      for (long long c = -1; c <= 1; ++c)
        if (s.count({std::get<0>(v) + a, std::get<1>(v) + b, std::get<2>(v) + c})) return true;
  return false;
}
std::vector<double> world_xyz(const PointCloud& c, const Pose& p) {
  std::vector<double> w(3 * c.size());
  for (std::size_t i = 0; i < c.size(); ++i)
    for (int r = 0; r < 3; ++r)
      w[3 * i + r] = p[4 * r] * c.xyzg[4 * i] + p[4 * r + 1] * c.xyzg[4 * i + 1] + p[4 * r + 2] * c.xyzg[4 * i + 2] +
                     p[4 * r + 3];
  return w;
}
std::vector<float> regress_at(const Gmm& world_gmm, const Pose& pose, const PointCloud& c) {
  const Gmm local = transform(world_gmm, inverse_rigid(pose));
  std::vector<float> xyz(3 * c.size()), g(c.size());
  for (std::size_t i = 0; i < c.size(); ++i)
    for (int j = 0; j < 3; ++j) xyz[3 * i + j] = c.xyzg[4 * i + j];
  regress_gray(local, xyz.data(), c.size(), g.data(), nullptr);
  return g;
}
double quantile(std::vector<double> v, double q) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(q * (v.size() - 1))];
}
}  // namespace

int main(int argc, char** argv) {
  CLI::App app("map gray-error diagnosis (issue 18)");
  tools::FrameSource src;
  std::size_t target = 0;
  MapOptions o;
  o.depth.decimate = 5;
  o.fit.bandwidth = 0.02;
  app.add_option("DIR", src.sequence)->required();
  app.add_option("--trajectory", src.trajectory)->required();
  app.add_option("--frames", src.frames);
  app.add_option("--frame", target)->required();
  app.add_option("--decimate", o.depth.decimate);
  app.add_option("--bandwidth", o.fit.bandwidth);
  app.add_option("--threshold", o.novelty_threshold);
  CLI11_PARSE(app, argc, argv);
  try {
    const tools::SequenceInput in = tools::resolve_sequence(src, {});
    Map map(o);
    std::set<Voxel> pending;
    PointCloud frame_cloud;
    Pose frame_pose{};
    Camera camera{};
    std::vector<double> score;
    std::vector<int> cls;  // 0 explained, 1 pending, 2 novel
    std::size_t replay_mismatch = 0;
    for (std::size_t k = 0; k < in.selected.size(); ++k) {
      const tools::SequenceFrame& f = in.frames[in.selected[k]];
      const tools::LoadedFrame lf = tools::load_frame(f.depth, f.color);
      camera = tools::resolve_camera(in.camera, lf);
      const PointCloud c = backproject(lf.view(camera), o.depth);
      const Pose& pose = in.poses[k];
      const std::vector<double> w = world_xyz(c, pose);
      std::vector<double> ll(c.size(), -INFINITY);
      if (map.size() > 0) map.local_log_likelihood(w.data(), c.size(), ll.data());
      std::vector<int> k_cls(c.size(), 0);
      std::vector<Voxel> added;
      std::size_t novel = 0;
      for (std::size_t i = 0; i < c.size(); ++i) {
        if (ll[i] >= o.novelty_threshold) continue;
        const Voxel v = voxel_of(w.data() + 3 * i);
        if (near(pending, v)) {
          k_cls[i] = 1;
        } else {
          k_cls[i] = 2;
          ++novel;
          added.push_back(v);
        }
      }
      pending.insert(added.begin(), added.end());
      const FrameStats st = map.insert_rgbd(lf.view(camera), pose);
      if (st.n_novel != novel) ++replay_mismatch;
      if (st.flushed) pending.clear();
      if (f.index == target) {
        frame_cloud = c;
        frame_pose = pose;
        score = ll;
        cls = k_cls;
      }
    }
    map.flush();
    require(!score.empty(), ErrorCode::InvalidArgument, "--frame is not among the selected frames");
    // The frame's own fit: that frame alone through an append-everything map.
    MapOptions own_o = o;
    own_o.novelty = false;
    Map own(own_o);
    {
      const tools::SequenceFrame& f = in.frames[target];
      const tools::LoadedFrame lf = tools::load_frame(f.depth, f.color);
      own.insert_rgbd(lf.view(camera), frame_pose);
    }
    const std::vector<float> g_map = regress_at(map.model().gmm, frame_pose, frame_cloud);
    const std::vector<float> g_own = regress_at(own.model().gmm, frame_pose, frame_cloud);
    const Camera dc = decimated(camera, o.depth.decimate);
    const double psnr_map = psnr(transform(map.model().gmm, inverse_rigid(frame_pose)), frame_cloud.view(), dc).psnr;
    const double psnr_own = psnr(transform(own.model().gmm, inverse_rigid(frame_pose)), frame_cloud.view(), dc).psnr;
    const std::size_t n = frame_cloud.size();
    double se_map[3] = {0, 0, 0}, se_own[3] = {0, 0, 0};
    std::size_t count[3] = {0, 0, 0};
    std::vector<double> score_worse[3];  // 3-D scores of points whose error grew by > 0.01 (0.1 gray)
    for (std::size_t i = 0; i < n; ++i) {
      const double t = frame_cloud.xyzg[4 * i + 3];
      const double em = (g_map[i] - t) * (g_map[i] - t), eo = (g_own[i] - t) * (g_own[i] - t);
      se_map[cls[i]] += em;
      se_own[cls[i]] += eo;
      ++count[cls[i]];
      if (em - eo > 0.01) score_worse[cls[i]].push_back(score[i]);
    }
    const double total_map = se_map[0] + se_map[1] + se_map[2], total_own = se_own[0] + se_own[1] + se_own[2];
    const char* names[3] = {"explained (3-D score >= threshold)", "pending (below, near a pending point)",
                            "novel"};
    std::printf("frame %zu: %zu points; map %zu components; PSNR map %.2f dB, own fit %.2f dB (loss %.2f dB; "
                "per-point MSE map %.5f, own %.5f); pending-rule replay mismatches: %zu frames\n",
                target, n, map.size(), psnr_map, psnr_own, psnr_own - psnr_map, total_map / n, total_own / n,
                replay_mismatch);
    std::printf("| class | points | share | MSE map | MSE own | share of the SE increase | 3-D score p10/p50/p90 | "
                "points worse by >0.1 gray: n, score p10/p50/p90 |\n|---|---|---|---|---|---|---|---|\n");
    nlohmann::json j;
    j["frame"] = target;
    j["points"] = n;
    j["psnr_map"] = psnr_map;
    j["psnr_own"] = psnr_own;
    j["replay_mismatch_frames"] = replay_mismatch;
    for (int c = 0; c < 3; ++c) {
      std::vector<double> s;
      for (std::size_t i = 0; i < n; ++i)
        if (cls[i] == c) s.push_back(score[i]);
      const double share_inc = (se_map[c] - se_own[c]) / (total_map - total_own);
      std::printf("| %s | %zu | %.1f%% | %.5f | %.5f | %.1f%% | %.2f / %.2f / %.2f | %zu, %.2f / %.2f / %.2f |\n",
                  names[c], count[c], 100.0 * count[c] / n, count[c] ? se_map[c] / count[c] : 0.0,
                  count[c] ? se_own[c] / count[c] : 0.0, 100 * share_inc, quantile(s, 0.1), quantile(s, 0.5),
                  quantile(s, 0.9), score_worse[c].size(), quantile(score_worse[c], 0.1),
                  quantile(score_worse[c], 0.5), quantile(score_worse[c], 0.9));
      nlohmann::json r;
      r["points"] = count[c];
      r["se_map"] = se_map[c];
      r["se_own"] = se_own[c];
      r["share_of_increase"] = share_inc;
      r["score_p50"] = quantile(s, 0.5);
      j[c == 0 ? "explained" : c == 1 ? "pending" : "novel"] = r;
    }
    std::printf("%s\n", j.dump().c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sogmm-map-gray-diag: %s\n", e.what());
    return 1;
  }
  return 0;
}
