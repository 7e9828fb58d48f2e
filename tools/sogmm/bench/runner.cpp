#include "runner.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "cli_common.hpp"
#include "file_util.hpp"
#include "ndt_map.hpp"
#include "octomap_adapter.hpp"
#include "sogmm/error.hpp"
#include "sogmm/fit.hpp"
#include "sogmm/fit_record.hpp"
#include "sogmm/inference.hpp"
#include "sogmm/metrics.hpp"

#ifdef SOGMM_BENCH_HAVE_FORMAT
#include "sogmm/format.hpp"
#endif

namespace sogmm::bench {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

std::string fmt_param(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

bool wants(const BenchConfig& c, const char* family) {
  return std::find(c.families.begin(), c.families.end(), family) != c.families.end();
}

/// PSNR of per-point gray predictions, projected like the GMM path.
PsnrResult psnr_of_predictions(const PointsView& truth, const std::vector<float>& predicted, const Camera& camera) {
  std::vector<float> gray(truth.size);
  for (std::size_t i = 0; i < truth.size; ++i) gray[i] = truth[i][3];
  const std::vector<float> t = project_to_image(truth, gray.data(), camera, -1.0f);
  const std::vector<float> e = project_to_image(truth, predicted.data(), camera, -1.0f);
  return psnr_images(t.data(), e.data(), t.size());
}

void fill_scores(BenchRow& row, const PsnrResult& p, const ReconstructionResult& r) {
  row.psnr = p.psnr;
  row.psnr_paper = p.psnr_paper;
  row.mre = r.mre;
  row.precision = r.precision;
  row.recall = r.recall;
  row.fscore = r.fscore;
}

long long sogmm_file_bytes(const FitResult& f, const FitOptions& o, const BenchConfig& config) {
#ifdef SOGMM_BENCH_HAVE_FORMAT
  Model model;
  model.gmm = f.gmm;
  record_fit(model, f, o);
  model.camera = config.camera_info;
  return static_cast<long long>(format::to_bytes(model).size());
#else
  (void)f;
  (void)o;
  (void)config;
  return -1;
#endif
}

/// The row of a voxel baseline (NDT, OctoMap) at `resolution` metres, named
/// method_prefix + resolution.
BenchRow voxel_row(const std::string& frame, const char* family, const char* method_prefix, double resolution,
                   const PointsView& truth) {
  BenchRow row;
  row.frame = frame;
  row.family = family;
  row.method = method_prefix + fmt_param(resolution);
  row.parameter = resolution;
  row.n_points = truth.size;
  return row;
}

/// Scores a built voxel baseline: the gray it predicts at every truth point
/// (counting the nearest-occupied-cell fallbacks) and the cloud `recon` it
/// reconstructs (x, y, z rows) against the truth.
template <typename VoxelMap>
void score_voxel_map(BenchRow& row, const VoxelMap& map, const std::vector<float>& recon, const PointsView& truth,
                     const Camera& camera, const BenchConfig& config) {
  std::vector<float> predicted(truth.size);
  for (std::size_t i = 0; i < truth.size; ++i) predicted[i] = map.gray_at(truth[i], &row.gray_fallbacks);
  fill_scores(row, psnr_of_predictions(truth, predicted, camera),
              compare_clouds(recon.data(), recon.size() / 3, 3, truth, config.threshold));
}

BenchRow run_gmm(const std::string& frame, const PointsView& truth, const Camera& camera, const BenchConfig& config,
                 const std::string& family, double bandwidth, std::size_t k) {
  BenchRow row;
  row.frame = frame;
  row.family = family;
  row.n_points = truth.size;
  FitOptions o;
  o.seed = config.seed;
  o.em = config.em;
  if (family == "fc") {
    o.n_components = std::min(k, truth.size);
    row.parameter = static_cast<double>(k);
    row.method = "FC-" + std::to_string(k);
    if (o.n_components < k) row.note = "K capped at N = " + std::to_string(truth.size);
  } else {
    o.bandwidth = bandwidth;
    row.parameter = bandwidth;
    row.method = "SOGMM-" + fmt_param(bandwidth);
  }
  // Exactly what `sogmm eval` does: fit, then tools::evaluate with the same seed.
  FitResult fitted = fit(truth, o);
  row.build_seconds = fitted.seconds_total;
  row.file_bytes = sogmm_file_bytes(fitted, o, config);
  const tools::Evaluation e = tools::evaluate(std::move(fitted), truth, camera, config.seed);
  fill_scores(row, e.psnr, e.reconstruction);
  row.n_elements = e.fit.gmm.size();
  row.memory_bytes = static_cast<long long>(e.model_bytes);
  if (!e.fit.em.converged) row.note += std::string(row.note.empty() ? "" : "; ") + "EM not converged";
  return row;
}

BenchRow run_ndt(const std::string& frame, const PointsView& truth, const Camera& camera, const BenchConfig& config,
                 double voxel) {
  BenchRow row = voxel_row(frame, "ndt", "NDT-", voxel, truth);
  const auto t0 = Clock::now();
  NdtMap map(voxel);
  map.build(truth);
  row.build_seconds = seconds_since(t0);
  score_voxel_map(row, map, map.sample(truth.size, config.seed), truth, camera, config);
  row.n_elements = map.size();
  row.memory_bytes = static_cast<long long>(map.paper_bytes());
  return row;
}

BenchRow run_octomap(const std::string& frame, const PointsView& truth, const Camera& camera,
                     const BenchConfig& config, double resolution) {
  BenchRow row = voxel_row(frame, "octomap", "OM-", resolution, truth);
  const auto t0 = Clock::now();
  OctoMapModel map(resolution);
  map.build(truth, config.octomap_ray_cast);
  if (!config.octomap_ray_cast) row.note = "no ray casting (endpoints only)";
  row.build_seconds = seconds_since(t0);
  score_voxel_map(row, map, map.reconstruct(truth.size), truth, camera, config);
  row.n_elements = map.occupied_leaves();
  row.file_bytes = static_cast<long long>(map.file_bytes());
  row.memory_bytes = row.file_bytes;
  return row;
}

}  // namespace

void validate(const BenchConfig& c) {
  for (const std::string& f : c.families)
    require(f == "octomap" || f == "ndt" || f == "fc" || f == "sogmm", ErrorCode::InvalidArgument,
            "unknown bench method '" + f + "' (use octomap, ndt, fc, sogmm)");
  for (double r : c.octomap_resolutions)
    require(std::isfinite(r) && r > 0, ErrorCode::InvalidArgument, "OctoMap resolutions must be > 0");
  for (double r : c.ndt_resolutions)
    require(std::isfinite(r) && r > 0, ErrorCode::InvalidArgument, "NDT voxel sizes must be > 0");
  for (std::size_t k : c.fc_components) require(k > 0, ErrorCode::InvalidArgument, "FC component counts must be >= 1");
  for (double b : c.bandwidths)
    require(std::isfinite(b) && b > 0, ErrorCode::InvalidArgument, "SOGMM bandwidths must be > 0");
}

std::vector<BenchRow> run_frame(const std::string& frame, const PointsView& truth, const Camera& camera,
                                const BenchConfig& config, const std::function<void(const std::string&)>& log) {
  validate(config);
  require_finite_points(truth, "ground-truth cloud");
  auto say = [&](const std::string& s) {
    if (log) log(s);
  };
  auto done = [&](const BenchRow& r) {
    char buf[256];
    std::snprintf(buf, sizeof buf, "%s %s: M = %zu, built in %.3f s", r.frame.c_str(), r.method.c_str(), r.n_elements,
                  r.build_seconds);
    say(buf);
  };
  std::vector<BenchRow> rows;
  if (wants(config, "octomap")) {
    if (!octomap_available()) {
      say("OctoMap: not built into this sogmm (liboctomap-dev not found at configure time): OM rows skipped");
    } else {
      for (double r : config.octomap_resolutions) {
        rows.push_back(run_octomap(frame, truth, camera, config, r));
        done(rows.back());
      }
    }
  }
  if (wants(config, "ndt"))
    for (double r : config.ndt_resolutions) {
      rows.push_back(run_ndt(frame, truth, camera, config, r));
      done(rows.back());
    }
  if (wants(config, "fc"))
    for (std::size_t k : config.fc_components) {
      rows.push_back(run_gmm(frame, truth, camera, config, "fc", 0.0, k));
      done(rows.back());
    }
  if (wants(config, "sogmm"))
    for (double b : config.bandwidths) {
      rows.push_back(run_gmm(frame, truth, camera, config, "sogmm", b, 0));
      done(rows.back());
    }
  return rows;
}

namespace {
std::string num(double v, const char* f) {
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  if (std::isnan(v)) return "nan";
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}
std::string bytes_or_dash(long long b) { return b < 0 ? "-" : std::to_string(b); }
std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) out += (c == '"') ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}
}  // namespace

std::string markdown_table(const std::vector<BenchRow>& rows) {
  std::ostringstream o;
  o << "| frame | method | N | M | PSNR (dB) | PSNR paper-compat (dB) | MRE (m) | precision | recall | F-score"
       " | memory (MB, paper) | file (bytes) | build (s) |\n";
  o << "|---|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|\n";
  for (const BenchRow& r : rows) {
    o << "| " << r.frame << " | " << r.method << " | " << r.n_points << " | " << r.n_elements << " | "
      << num(r.psnr, "%.2f") << " | " << num(r.psnr_paper, "%.2f") << " | " << num(r.mre, "%.4f") << " | "
      << num(r.precision, "%.3f") << " | " << num(r.recall, "%.3f") << " | " << num(r.fscore, "%.3f") << " | "
      << (r.memory_bytes < 0 ? std::string("-") : num(r.memory_bytes / 1e6, "%.3f")) << " | "
      << bytes_or_dash(r.file_bytes) << " | " << num(r.build_seconds, "%.3f") << " |\n";
  }
  return o.str();
}

void write_csv(const std::string& path, const std::vector<BenchRow>& rows) {
  std::ostringstream f;
  f << "frame,method,family,parameter,n_points,n_elements,psnr,psnr_paper,mre,precision,recall,fscore,"
       "memory_bytes,file_bytes,build_seconds,gray_fallbacks,note\n";
  for (const BenchRow& r : rows) {
    f << csv_field(r.frame) << ',' << r.method << ',' << r.family << ',' << num(r.parameter, "%g") << ','
      << r.n_points << ',' << r.n_elements << ',' << num(r.psnr, "%.6f") << ',' << num(r.psnr_paper, "%.6f") << ','
      << num(r.mre, "%.8f") << ',' << num(r.precision, "%.6f") << ',' << num(r.recall, "%.6f") << ','
      << num(r.fscore, "%.6f") << ',' << (r.memory_bytes < 0 ? std::string() : std::to_string(r.memory_bytes)) << ','
      << (r.file_bytes < 0 ? std::string() : std::to_string(r.file_bytes)) << ',' << num(r.build_seconds, "%.6f")
      << ',' << r.gray_fallbacks << ',' << csv_field(r.note) << '\n';
  }
  const std::string text = f.str();
  tools::write_file_atomic(path, text.data(), text.size());
}

}  // namespace sogmm::bench
