// Warm-start benchmark (issue 17): fits frame A of a posed sequence, moves the
// model by the relative pose into frame B's camera and times the warm fit of
// B against a cold fit of B, interleaved in one process (median of --repeat).
// Prints one JSON object: N and M of both fits, median seconds, the warm
// start's kept/removed/added components, both mean log-likelihoods and both
// PSNRs, so quality and speed come from the same run.
//
// Usage: sogmm-bench-warm --sequence DIR --trajectory LOG --from A --to B
//        --decimate d --bandwidth S [--threads T] [--repeat R] [--seed s]
//        [--warm-max-iter P] [--warm-tol-standard-errors c] [--warm-em-acceleration 1]
//        [--min-mass m] [--novelty-nats n]
#include <cstdlib>
#include <cstdio>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "image_io.hpp"
#include "sequence.hpp"
#include "sogmm/camera.hpp"
#include "sogmm/inference.hpp"
#include "sogmm/loop_accounting.hpp"
#include "sogmm/metrics.hpp"
#include "sogmm/warm_start.hpp"
#include "median.hpp"

namespace {
using sogmm::perf::median;
}  // namespace

int main(int argc, char** argv) {
  using namespace sogmm;
  CLI::App app{"sogmm-bench-warm: warm-started vs cold fit of the next frame"};
  std::string dir, trajectory;
  std::size_t from = 0, to = 1;
  int repeat = 5;
  DepthOptions opt;
  FitOptions fo;
  app.add_option("--sequence", dir)->required();
  app.add_option("--trajectory", trajectory)->required();
  app.add_option("--from", from);
  app.add_option("--to", to);
  app.add_option("--decimate", opt.decimate);
  app.add_option("--bandwidth", fo.bandwidth);
  app.add_option("--threads", fo.em.threads);
  app.add_option("--seed", fo.seed);
  app.add_option("--repeat", repeat);
  WarmStartOptions wo;
  // The warm fit's own EM settings (the cold fit keeps the defaults).
  FitOptions wf = fo;
  int warm_acceleration = static_cast<int>(wf.em.acceleration);
  app.add_option("--warm-max-iter", wo.max_iter,
                 "EM pass limit of the warm fit (WarmStartOptions::max_iter; 0 = as the cold fit)")
      ->capture_default_str();
  app.add_option("--warm-tol-standard-errors", wf.em.tol_standard_errors, "the warm fit's noise-aware stop");
  app.add_option("--warm-em-acceleration", warm_acceleration, "the warm fit's EM acceleration (1: SQUAREM)");
  std::vector<int> sweep;
  app.add_option("--sweep-max-iter", sweep,
                 "after the timed runs, one warm fit per pass cap given, each printed as one JSON line before the "
                 "main object (quality only: the caps share the cold fit)")
      ->delimiter(',');
  app.add_option("--min-mass", wo.min_mass);
  app.add_option("--novelty-nats", wo.novelty_nats);
  CLI11_PARSE(app, argc, argv);
  wf.bandwidth = fo.bandwidth;
  wf.em.threads = fo.em.threads;
  wf.seed = fo.seed;
  wf.em.acceleration = static_cast<EmAcceleration>(warm_acceleration);

  const std::vector<tools::SequenceFrame> frames = tools::list_sequence(dir);
  const std::vector<tools::Pose> poses = tools::read_trajectory(trajectory);
  const Camera camera = read_intrinsics_json(dir + "/intrinsics.json");
  auto cloud_of = [&](std::size_t i) {
    const tools::LoadedFrame f = tools::load_frame(frames.at(i).depth, frames.at(i).color);
    return backproject(f.view(camera), opt);
  };
  const PointCloud a = cloud_of(from), b = cloud_of(to);
  // Camera A -> world -> camera B.
  const Gmm moved = transform(fit(a.view(), fo).gmm, sogmm::compose_poses(tools::inverse_rigid(poses.at(to)), poses.at(from)));

  if (std::getenv("SOGMM_POSECHECK")) {
    const Gmm ga = fit(a.view(), fo).gmm;
    const tools::Pose rel = sogmm::compose_poses(tools::inverse_rigid(poses.at(to)), poses.at(from));
    const tools::Pose id{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    std::printf("A on A %.4f; rel %.4f; id %.4f; inv rel %.4f\n", mean_log_likelihood(ga, a.xyzg.data(), a.size(), 4),
                mean_log_likelihood(transform(ga, rel), b.xyzg.data(), b.size(), 4),
                mean_log_likelihood(transform(ga, id), b.xyzg.data(), b.size(), 4),
                mean_log_likelihood(transform(ga, tools::inverse_rigid(rel)), b.xyzg.data(), b.size(), 4));
  }
  std::vector<double> cold_s, warm_s;
  FitResult cold, warm;
  WarmStartReport rep;
  // The warm fits' CPU on this thread, and the part outside the core's
  // parallel loops (sogmm/loop_accounting.hpp), summed over the repeats: on
  // one thread, the serial share that bounds the two-thread speed-up.
  double warm_cpu = 0.0, warm_serial_cpu = 0.0, warm_wall = 0.0;
  std::uint64_t warm_loops = 0;
  // On a team: the split of the warm fits' loop wall time (team_* of
  // LoopAccounting), summed over the repeats.
  LoopAccounting team;
  set_loop_accounting(true);
  for (int r = 0; r < repeat; ++r) {
    const double cpu0 = thread_cpu_seconds();
    const LoopAccounting acc0 = loop_accounting();
    warm = fit_warm(b.view(), moved, wf, {}, wo, &rep);
    const LoopAccounting acc1 = loop_accounting();
    const double cpu = thread_cpu_seconds() - cpu0;
    warm_cpu += cpu;
    warm_serial_cpu += cpu - (acc1.cpu_seconds_in_loops - acc0.cpu_seconds_in_loops);
    warm_loops += acc1.loops - acc0.loops;
    team.team_loops += acc1.team_loops - acc0.team_loops;
    team.team_wall_seconds += acc1.team_wall_seconds - acc0.team_wall_seconds;
    team.team_busy_seconds += acc1.team_busy_seconds - acc0.team_busy_seconds;
    team.team_start_seconds += acc1.team_start_seconds - acc0.team_start_seconds;
    team.team_imbalance_seconds += acc1.team_imbalance_seconds - acc0.team_imbalance_seconds;
    team.team_join_seconds += acc1.team_join_seconds - acc0.team_join_seconds;
    warm_wall += warm.seconds_total;
    warm_s.push_back(warm.seconds_total);
    cold = fit(b.view(), fo);
    cold_s.push_back(cold.seconds_total);
  }
  set_loop_accounting(false);
  const Camera dc = decimated(camera, opt.decimate);
  for (const int cap : sweep) {
    WarmStartOptions capped = wo;
    capped.max_iter = cap;
    const FitResult r = fit_warm(b.view(), moved, wf, {}, capped);
    std::printf("{\"warm_max_iter\": %d, \"m_warm\": %zu, \"s_warm\": %.6f, \"iter_warm\": %d, \"ll_warm\": %.6f, "
                "\"psnr_warm\": %.4f}\n",
                cap, r.gmm.size(), r.seconds_total, r.em.iterations, r.em.log_likelihood, psnr(r.gmm, b.view(), dc).psnr);
  }
  const double psnr_cold = psnr(cold.gmm, b.view(), dc).psnr, psnr_warm = psnr(warm.gmm, b.view(), dc).psnr;
  std::printf(
      "{\"n\": %zu, \"m_cold\": %zu, \"m_warm\": %zu, \"m_initial\": %zu, \"kept\": %zu, \"removed\": %zu, "
      "\"added\": %zu, \"novel_points\": %zu, \"s_cold\": %.6f, \"s_warm\": %.6f, \"s_warm_score\": %.6f, "
      "\"s_warm_mode_count\": %.6f, \"s_warm_seeding\": %.6f, \"s_warm_em\": %.6f, \"iter_cold\": %d, "
      "\"iter_warm\": %d, \"ll_cold\": %.6f, \"ll_warm\": %.6f, \"psnr_cold\": %.4f, \"psnr_warm\": %.4f, "
      "\"cpu_warm\": %.6f, \"serial_cpu_warm\": %.6f, \"loops_warm\": %llu, \"wall_warm\": %.6f, "
      "\"team_loops_warm\": %llu, \"team_wall_warm\": %.6f, \"team_busy_warm\": %.6f, \"team_start_warm\": %.6f, "
      "\"team_imbalance_warm\": %.6f, \"team_join_warm\": %.6f}\n",
      b.size(), cold.gmm.size(), warm.gmm.size(), moved.size(), rep.kept, rep.removed, rep.added, rep.novel_points,
      median(cold_s), median(warm_s), rep.seconds_score, warm.seconds_mode_count, warm.seconds_seeding,
      warm.seconds_em, cold.em.iterations, warm.em.iterations, cold.em.log_likelihood, warm.em.log_likelihood,
      psnr_cold, psnr_warm, warm_cpu / repeat, warm_serial_cpu / repeat,
      static_cast<unsigned long long>(warm_loops / static_cast<std::uint64_t>(repeat)), warm_wall / repeat,
      static_cast<unsigned long long>(team.team_loops / static_cast<std::uint64_t>(repeat)),
      team.team_wall_seconds / repeat, team.team_busy_seconds / repeat, team.team_start_seconds / repeat,
      team.team_imbalance_seconds / repeat, team.team_join_seconds / repeat);
  return 0;
}
