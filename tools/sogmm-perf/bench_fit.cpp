// Performance benchmark of one SOGMM fit (issue 8): prints one JSON object
// with N, M, seconds per stage (mode count, seeding, EM, regression,
// score_samples, sampling, metrics), the EM kernel's peak pairs per second
// (ten exact passes from the fitted model), EM iterations, ms per EM iteration, achieved GFLOP/s of
// the EM passes, and the process's peak resident memory. Driven by
// tests/benchmarks/run_perf.py, which repeats cases and adds the
// scikit-learn peer.
//
// Usage: sogmm_bench_fit --depth D --color C --intrinsics J --decimate d
//        --bandwidth S [--threads T] [--depth-scale 1000] [--tol T] [--tol-standard-errors C]
//        [--em-acceleration none|squarem]
//        [--dump-points FILE]
//
// FLOP count per point-component pair per EM iteration: 80 (log-density 30,
// exp and log-sum-exp 16 counting exp as 15 like the prototype, and
// sufficient statistics 34). The GFLOP/s figure is 80 * N * M * iterations *
// pair_fraction / EM seconds: an effective rate, since the pairs of rows that
// the kernel skips exactly (every responsibility 0 in float) are counted too;
// pair_fraction < 1 only for the truncated E-step.
//
// Quality beside the speed: the training log-likelihood, and the held-out
// figures of `sogmm eval` (issue 29 item 1; eval_pixels.hpp): the mean
// log-likelihood per point on the held-out grid (the d + 1 grid minus the
// fitting grid, pixels the fit never saw) and the per-pixel PSNR of the
// model's render there. Computed after every timed stage.
#include <time.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <string>

#include <CLI/CLI.hpp>

#include "cli_common.hpp"
#include "eval_pixels.hpp"
#include "frame_flags.hpp"
#include "sogmm/camera.hpp"
#include "sogmm/fit.hpp"
#include "sogmm/inference.hpp"
#include "sogmm/kmeanspp.hpp"
#include "sogmm/loop_accounting.hpp"
#include "sogmm/metrics.hpp"

namespace {
// CPU clocks at one instant: the calling thread's, the parallel loops' share
// of it, and the process's.
struct CpuMark {
  double thread = 0.0, in_loops = 0.0, process = 0.0, wall = 0.0;
  std::uint64_t loops = 0;
  sogmm::LoopAccounting acc;
  static CpuMark now() {
    CpuMark m;
    m.thread = sogmm::thread_cpu_seconds();
    const sogmm::LoopAccounting a = sogmm::loop_accounting();
    m.acc = a;
    m.in_loops = a.cpu_seconds_in_loops;
    m.loops = a.loops;
    m.wall = std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    m.process = static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
    return m;
  }
};

// A JSON number, or null where there is none: at d = 1 every pixel of the
// d + 1 grid is on the fitting grid, so the held-out figures are NaN.
std::string json_number(double v) {
  if (!std::isfinite(v)) return "null";
  char text[32];
  std::snprintf(text, sizeof text, "%.6f", v);
  return text;
}

// Per stage: "cpu_S", "serial_cpu_S", "loops_S", "pcpu_S", and the team
// split of the wall time (sogmm/loop_accounting.hpp): "wall_S" and
// "team_{loops,wall,busy,start,imbalance,join}_S", as JSON members (each with
// a leading ", ").
std::string cpu_json(const std::string& stage, const CpuMark& a, const CpuMark& b) {
  const char* st = stage.c_str();
  char buf[768];
  std::snprintf(buf, sizeof buf,
                ", \"cpu_%s\": %.6f, \"serial_cpu_%s\": %.6f, \"loops_%s\": %llu, \"pcpu_%s\": %.6f, \"wall_%s\": %.6f, "
                "\"team_loops_%s\": %llu, \"team_wall_%s\": %.6f, \"team_busy_%s\": %.6f, \"team_start_%s\": %.6f, "
                "\"team_imbalance_%s\": %.6f, \"team_join_%s\": %.6f",
                st, b.thread - a.thread, st, (b.thread - a.thread) - (b.in_loops - a.in_loops), st,
                static_cast<unsigned long long>(b.loops - a.loops), st, b.process - a.process, st, b.wall - a.wall, st,
                static_cast<unsigned long long>(b.acc.team_loops - a.acc.team_loops), st,
                b.acc.team_wall_seconds - a.acc.team_wall_seconds, st, b.acc.team_busy_seconds - a.acc.team_busy_seconds,
                st, b.acc.team_start_seconds - a.acc.team_start_seconds, st,
                b.acc.team_imbalance_seconds - a.acc.team_imbalance_seconds, st,
                b.acc.team_join_seconds - a.acc.team_join_seconds);
  return buf;
}
}  // namespace

int main(int argc, char** argv) {
  using namespace sogmm;
  CLI::App app{"sogmm-perf: time one fit and its inference stages"};
  perf::FrameFlags in;
  std::string dump;
  FitOptions fit_options;
  in.add_to(app);
  app.add_option("--depth-scale", in.depth_options.depth_scale);
  app.add_option("--bandwidth", fit_options.bandwidth);
  app.add_option("--threads", fit_options.em.threads);
  app.add_option("--seed", fit_options.seed);
  app.add_option("--truncate", fit_options.em.truncation_nats, "truncated E-step cutoff in nats (0 = exact)");
  app.add_option("--tol", fit_options.em.tol, "EM tolerance on the mean log-likelihood (default: the library's)");
  app.add_option("--tol-standard-errors", fit_options.em.tol_standard_errors,
                 "EM also stops below this many standard errors of the mean log-likelihood (default: the library's)");
  tools::add_em_acceleration_flag(app, fit_options.em);
  double query_nats = 20.0;
  app.add_option("--query-truncate", query_nats, "culled regress/score rows: cutoff in nats (0 = skip those rows)");
  app.add_option("--dump-points", dump, "write N x 4 float32 points, then the seed indices (uint64) to FILE");
  CLI11_PARSE(app, argc, argv);

  const Camera camera = in.camera();
  const PointCloud cloud = in.cloud();
  // The CPU clocks at the start of each stage (the progress reports come on
  // this thread), then at the end of the fit.
  set_loop_accounting(true);
  std::map<Stage, CpuMark> stage_start;
  const CpuMark fit_start = CpuMark::now();
  const FitResult r = fit(cloud.view(), fit_options, [&](const Progress& p) {
    if (!stage_start.count(p.stage)) stage_start[p.stage] = CpuMark::now();
    return false;
  });
  const CpuMark fit_end = CpuMark::now();
  std::string cpu = cpu_json("fit", fit_start, fit_end);
  {
    const Stage order[] = {Stage::ModeCount, Stage::Seeding, Stage::Em};
    const char* names[] = {"mode_count", "seeding", "em"};
    for (int i = 0; i < 3; ++i) {
      if (!stage_start.count(order[i])) continue;
      const CpuMark end = i < 2 && stage_start.count(order[i + 1]) ? stage_start[order[i + 1]] : fit_end;
      cpu += cpu_json(names[i], stage_start[order[i]], end);
    }
  }
  const std::size_t n = cloud.size(), m = r.gmm.size();

  using clock = std::chrono::steady_clock;
  auto t = clock::now();
  std::vector<float> xyz(3 * n), mean(n), var(n);
  for (std::size_t i = 0; i < n; ++i)
    for (int j = 0; j < 3; ++j) xyz[3 * i + j] = cloud.xyzg[4 * i + j];
  // The queries run on the fit's team, so the 1-thread rows are 1 thread.
  QueryOptions query_options;
  query_options.threads = fit_options.em.threads;
  CpuMark mark = CpuMark::now();
  regress_gray(r.gmm, xyz.data(), n, mean.data(), var.data(), query_options);
  cpu += cpu_json("regress", mark, CpuMark::now());
  const double s_regress = std::chrono::duration<double>(clock::now() - t).count();
  t = clock::now();
  std::vector<double> scores(n);
  mark = CpuMark::now();
  score_samples(r.gmm, cloud.xyzg.data(), n, 4, scores.data(), query_options);
  cpu += cpu_json("score", mark, CpuMark::now());
  const double s_score = std::chrono::duration<double>(clock::now() - t).count();
  // The same two queries culled (QueryOptions::truncation_nats).
  double s_regress_culled = 0.0, s_score_culled = 0.0;
  if (query_nats > 0) {
    QueryOptions culled = query_options;
    culled.truncation_nats = query_nats;
    t = clock::now();
    mark = CpuMark::now();
    regress_gray(r.gmm, xyz.data(), n, mean.data(), var.data(), culled);
    cpu += cpu_json("regress_culled", mark, CpuMark::now());
    s_regress_culled = std::chrono::duration<double>(clock::now() - t).count();
    t = clock::now();
    mark = CpuMark::now();
    score_samples(r.gmm, cloud.xyzg.data(), n, 4, scores.data(), culled);
    cpu += cpu_json("score_culled", mark, CpuMark::now());
    s_score_culled = std::chrono::duration<double>(clock::now() - t).count();
  }
  // The EM kernel's peak on this machine: exact E+M passes (tol 0) from the
  // fitted model, where the kernel is all the work; pairs per second.
  EmOptions peak_options = fit_options.em;
  peak_options.tol = 0.0;
  peak_options.max_iter = 10;
  peak_options.truncation_nats = 0.0;
  t = clock::now();
  set_loop_accounting(false);
  EmReport peak_report;
  fit_em_from(cloud.view(), r.gmm, peak_options, &peak_report);
  const double peak_pairs_per_s =
      static_cast<double>(n) * m * peak_report.iterations / std::chrono::duration<double>(clock::now() - t).count();
  t = clock::now();
  std::vector<float> samples(4 * n);
  sample(r.gmm, n, 1, 4, samples.data());
  const double s_sample = std::chrono::duration<double>(clock::now() - t).count();
  t = clock::now();
  const PsnrResult p = psnr(r.gmm, cloud.view(), decimated(camera, in.depth_options.decimate));
  const ReconstructionResult rec = reconstruction_metrics(r.gmm, cloud.view(), 0.01, 0);
  const double s_metrics = std::chrono::duration<double>(clock::now() - t).count();
  const tools::PixelFigures held = tools::pixel_figures(r.gmm, in.frame(), camera, in.depth_options, 1.0, 0.0);

  if (!dump.empty()) {
    // Points and the k-means++ seeds of this fit, for the scikit-learn peer.
    const std::vector<std::size_t> seeds = kmeanspp_seeds(cloud.view(), m, fit_options.seed);
    std::ofstream out(dump, std::ios::binary);
    const std::uint64_t header[2] = {n, m};
    out.write(reinterpret_cast<const char*>(header), sizeof header);
    out.write(reinterpret_cast<const char*>(cloud.xyzg.data()), cloud.xyzg.size() * sizeof(float));
    for (std::size_t s : seeds) {
      const std::uint64_t v = s;
      out.write(reinterpret_cast<const char*>(&v), sizeof v);
    }
  }
  // Peak resident memory of this process image: VmHWM (ru_maxrss would also
  // count the parent's memory at fork time).
  double peak_rss_kib = 0.0;
  {
    std::ifstream status("/proc/self/status");
    std::string key;
    while (status >> key) {
      if (key == "VmHWM:") {
        status >> peak_rss_kib;
        break;
      }
      std::getline(status, key);
    }
  }
  // Only the pairs the E-step evaluated count (all of them when exact).
  const double pairs = static_cast<double>(n) * m * r.em.iterations * r.em.pair_fraction;
  std::printf(
      "{\"n\": %zu, \"m\": %zu, \"s_mode_count\": %.6f, \"s_seeding\": %.6f, \"s_em\": %.6f, \"s_total_fit\": %.6f, "
      "\"em_iterations\": %d, \"ms_per_iteration\": %.4f, \"pair_fraction\": %.4f, \"gflops\": %.3f, \"s_regress\": %.6f, \"s_score\": %.6f, \"s_regress_culled\": %.6f, \"s_score_culled\": %.6f, \"peak_pairs_per_s\": %.6g, \"s_sample\": %.6f, "
      "\"s_metrics\": %.6f, \"peak_rss_mib\": %.1f, \"log_likelihood\": %.6f, \"psnr\": %.4f, \"mre\": %.6f, "
      "\"fscore\": %.4f, \"log_likelihood_heldout\": %s, \"pixel_psnr_heldout\": %s, \"heldout_decimate\": %d%s}\n",
      n, m, r.seconds_mode_count, r.seconds_seeding, r.seconds_em, r.seconds_total, r.em.iterations,
      1000.0 * r.seconds_em / r.em.iterations, r.em.pair_fraction, 80.0 * pairs / r.seconds_em * 1e-9, s_regress, s_score, s_regress_culled, s_score_culled, peak_pairs_per_s, s_sample, s_metrics,
      peak_rss_kib / 1024.0, r.em.log_likelihood, p.psnr, rec.mre, rec.fscore, json_number(held.log_likelihood_heldout).c_str(),
      json_number(held.heldout.psnr).c_str(), held.decimate + 1, cpu.c_str());
  return 0;
}
