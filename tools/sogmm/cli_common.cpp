#include "cli_common.hpp"

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <new>

#include "file_util.hpp"
#include "sigint_cancel.hpp"
#include "sogmm/checked.hpp"
#include "sogmm/error.hpp"
#include "sogmm/inference.hpp"
#include <memory>

namespace sogmm::tools {

namespace {
// Read here rather than by sogmm::read_intrinsics_json so that a FIFO or a
// device given as --intrinsics is refused at once (read_input_file).
Camera read_intrinsics(const std::string& path) {
  return parse_intrinsics_json(read_input_file(path, "intrinsics file"), path);
}
}  // namespace

void add_camera_flags(CLI::App& app, CameraFlags& c, DepthOptions& d) {
  app.add_option("--intrinsics", c.intrinsics, "Open3D PinholeCameraIntrinsic JSON file");
  app.add_option("--width", c.width, "image width (pixels), with --height --fx --fy --cx --cy");
  app.add_option("--height", c.height, "image height (pixels)");
  app.add_option("--fx", c.fx, "focal length x (pixels)");
  app.add_option("--fy", c.fy, "focal length y (pixels)");
  app.add_option("--cx", c.cx, "principal point x (pixels)");
  app.add_option("--cy", c.cy, "principal point y (pixels)");
  app.add_option("--depth-scale", d.depth_scale, "raw depth units per metre")->capture_default_str();
  app.add_option("--depth-min", d.depth_min, "valid depth > this (m)")->capture_default_str();
  app.add_option("--depth-max", d.depth_max, "valid depth <= this (m)")->capture_default_str();
  app.add_option("--decimate", d.decimate, "integer decimation factor (5: 640x480 -> 128x96)")->capture_default_str();
}

Camera resolve_camera(const CameraFlags& f, const LoadedFrame& frame) {
  Camera cam;
  const bool explicit_camera = f.fx > 0 || f.fy > 0 || f.width > 0 || f.height > 0;
  if (!f.intrinsics.empty()) {
    require(!explicit_camera, ErrorCode::InvalidArgument, "give either --intrinsics or --fx/--fy/--cx/--cy, not both");
    cam = read_intrinsics(f.intrinsics);
  } else {
    require(explicit_camera, ErrorCode::InvalidArgument,
            "no camera: give --intrinsics FILE or --fx --fy --cx --cy (and optionally --width --height)");
    cam = Camera{f.width > 0 ? f.width : frame.width, f.height > 0 ? f.height : frame.height, f.fx, f.fy, f.cx, f.cy};
    validate(cam);
  }
  require(cam.width == frame.width && cam.height == frame.height, ErrorCode::InvalidData,
          "camera is " + std::to_string(cam.width) + "x" + std::to_string(cam.height) + " but the images are " +
              std::to_string(frame.width) + "x" + std::to_string(frame.height));
  return cam;
}

void add_fit_flags(CLI::App& app, FitOptions& o) {
  auto* bw = app.add_option("--bandwidth", o.bandwidth, "mean-shift bandwidth (self-organizing fit)")->capture_default_str();
  auto* k = app.add_option("--components", o.n_components, "fixed number of components K (FC baseline)");
  bw->excludes(k);
  app.add_option("--seed", o.seed, "random seed (k-means++ and sampling)")->capture_default_str();
  app.add_option("--n-init", o.n_init,
                 "runs of k-means++ + EM with seeds seed, seed+1, ...; the highest log-likelihood is kept")
      ->capture_default_str()
      ->check(CLI::Range(1, kMaxRuns));
  // Frames are back-projected depth images, so the library's automatic
  // default already floors them; the flags force it either way.
  auto* on = app.add_flag_callback(
      "--dequantise-depth", [&o] { o.dequantise_depth = Dequantise::On; },
      "floor variances along viewing rays at the depth quantisation (the default for depth images)");
  auto* off = app.add_flag_callback(
      "--no-dequantise-depth", [&o] { o.dequantise_depth = Dequantise::Off; },
      "the paper's plain EM on quantised depth (components may collapse onto single depth levels)");
  on->excludes(off);
  app.add_option("--threads", o.em.threads, "worker threads (0 = all cores)")->capture_default_str();
  app.add_option("--tol", o.em.tol, "EM tolerance on the mean log-likelihood")->capture_default_str();
  app.add_option("--tol-standard-errors", o.em.tol_standard_errors,
                 "EM also stops when a pass gains less than this many standard errors of the mean "
                 "log-likelihood (when above --tol; 0: --tol alone)")
      ->capture_default_str();
  app.add_option("--max-iter", o.em.max_iter, "EM iteration limit")->capture_default_str();
  app.add_option_function<std::string>(
         "--reg-covar",
         [&o](const std::string& v) {
           if (v == "auto") {
             o.em.reg_covar.reset();
             return;
           }
           double r = 0.0;
           std::size_t used = 0;
           try {
             r = std::stod(v, &used);
           } catch (const std::exception&) {
             used = 0;
           }
           if (used != v.size() || !std::isfinite(r) || r < 0)
             throw CLI::ValidationError("--reg-covar", "must be auto or a finite number >= 0, got " + v);
           o.em.reg_covar = r;
         },
         "covariance regulariser: auto (floors from the data's spatial and gray scales; 1e-6 for a room with "
         "gray in [0, 1]) or one value added to all four diagonals")
      ->default_str("auto");
  app.add_option("--truncate", o.em.truncation_nats,
                 "truncated E-step: skip components provably this many nats below each point's best "
                 "(0 = exact; 20 is a good value for full frames)")
      ->capture_default_str();
  add_em_acceleration_flag(app, o.em);
}

void add_em_acceleration_flag(CLI::App& app, EmOptions& em) {
  app.add_option_function<std::string>(
         "--em-acceleration",
         [&em](const std::string& v) {
           if (v == "none") em.acceleration = EmAcceleration::None;
           else if (v == "squarem") em.acceleration = EmAcceleration::Squarem;
           else throw CLI::ValidationError("--em-acceleration", "must be none or squarem, got " + v);
         },
         "none: plain EM; squarem: SQUAREM steps (extrapolation along two EM steps, rejected when the "
         "likelihood would fall)")
      ->default_str(em.acceleration == EmAcceleration::Squarem ? "squarem" : "none");
}

PointCloud backproject_nonempty(const LoadedFrame& frame, const Camera& camera, const DepthOptions& depth,
                                const std::string& depth_path) {
  PointCloud cloud = backproject(frame.view(camera), depth);
  require(cloud.size() > 0, ErrorCode::InvalidData,
          depth_path + ": no valid depth pixel in (" + checked::exact(depth.depth_min) + ", " +
              checked::exact(depth.depth_max) + "] m (check --depth-scale)");
  return cloud;
}

void add_frame_source_flags(CLI::App& app, FrameSource& f, const std::string& sequence_use) {
  app.add_option("--depth", f.depth, "16-bit depth PNG");
  app.add_option("--color", f.color, "color or gray image (PNG/JPEG), registered to the depth");
  app.add_option("--sequence", f.sequence,
                 sequence_use + "folder with depth/*.png and color/*.{jpg,png} (instead of --depth/--color)");
  app.add_option("--trajectory", f.trajectory, "with --sequence: Redwood .log camera-to-world poses");
  app.add_option("--frames", f.frames, "with --sequence: I, A:B (B excluded) or A:B:STEP; default all");
  add_pair_by_order_flag(app, f.pair_by_order);
}

void add_pair_by_order_flag(CLI::App& app, bool& pair_by_order) {
  app.add_flag("--pair-by-order", pair_by_order,
               "with --sequence: pair images and poses by file order, ignoring the frame numbers of the image "
               "names and of the trajectory (default: by number, mismatches refused)");
}

void add_data_range_flag(CLI::App& app, double& data_range) {
  app.add_option("--data-range", data_range,
                 "peak of the honest PSNR: 1 for gray in [0, 1], 0 = the frame's actual gray range (max - min); "
                 "the paper-compatible PSNR always uses the authors' 2")
      ->capture_default_str();
}

Evaluation evaluate(FitResult fit, const PointsView& truth, const Camera& decimated_camera, std::uint64_t seed,
                    double data_range) {
  Evaluation e;
  e.psnr = psnr(fit.gmm, truth, decimated_camera, data_range);
  e.reconstruction = reconstruction_metrics(fit.gmm, truth, 0.01, seed);
  e.model_bytes = paper_model_bytes(fit.gmm);
  e.fit = std::move(fit);
  return e;
}

bool any_given(const CLI::App& app, std::initializer_list<const char*> names) {
  for (const char* n : names)
    if (app.count(n) > 0) return true;
  return false;
}

bool camera_flags_given(const CameraFlags& f) {
  return !f.intrinsics.empty() || f.fx > 0 || f.fy > 0 || f.width > 0 || f.height > 0 || f.cx != 0 || f.cy != 0;
}

Camera camera_from_flags(const CameraFlags& f) {
  const bool explicit_camera = f.fx > 0 || f.fy > 0 || f.width > 0 || f.height > 0;
  if (!f.intrinsics.empty()) {
    require(!explicit_camera, ErrorCode::InvalidArgument, "give either --intrinsics or --fx/--fy/--cx/--cy, not both");
    return read_intrinsics(f.intrinsics);
  }
  require(f.width > 0 && f.height > 0 && f.fx > 0 && f.fy > 0, ErrorCode::InvalidArgument,
          "camera flags need all of --width --height --fx --fy --cx --cy (or --intrinsics FILE)");
  const Camera cam{f.width, f.height, f.fx, f.fy, f.cx, f.cy};
  validate(cam);
  return cam;
}

ProgressMode progress_mode(bool quiet, bool lines) {
  if (quiet) return ProgressMode::Off;
  if (::isatty(::fileno(stderr))) return ProgressMode::Live;
  return lines ? ProgressMode::Lines : ProgressMode::Off;
}

void ProgressPrinter::show(const std::string& text, bool keep) {
  if (mode_ == ProgressMode::Off) return;
  if (mode_ == ProgressMode::Lines) {
    std::fprintf(stderr, "%s\n", text.c_str());
  } else {
    std::fprintf(stderr, "\r\033[2K%s%s", text.c_str(), keep ? "\n" : "");
    live_pending_ = !keep;
  }
  std::fflush(stderr);
}

void ProgressPrinter::line(const std::string& text) { show(text, true); }

void ProgressPrinter::finish() {
  if (mode_ == ProgressMode::Live && live_pending_) {
    std::fprintf(stderr, "\r\033[2K");
    std::fflush(stderr);
    live_pending_ = false;
  }
}

void ProgressPrinter::status(const std::string& text) { show(text, mode_ != ProgressMode::Live); }

void ProgressPrinter::em_done(const std::string& label, const FitResult& r) {
  em_done(label, r.seconds_em, r.em.iterations, r.em.log_likelihood);
}

void ProgressPrinter::em_done(const std::string& label, double seconds_em, int iterations, double log_likelihood) {
  if (mode_ != ProgressMode::Lines) return;
  char buf[160];
  std::snprintf(buf, sizeof buf, "EM done in %.3f s: %d iterations, mean log-likelihood %.4f", seconds_em, iterations,
                log_likelihood);
  show(label + ": " + buf, true);
}

ProgressSink ProgressPrinter::fit_callback(const std::string& label) {
  struct Clock {
    std::chrono::steady_clock::time_point start;
    std::string done;  // finished stages, "mode count 0.04 s, seeding 0.12 s"
    const char* current = nullptr;
    Stage stage{};
    std::uint64_t step = 0;
    bool started = false;
  };
  auto c = std::make_shared<Clock>();
  return [this, c, label](const Progress& p) {
    if (SigintCancel::requested()) return true;
    if (mode_ == ProgressMode::Off) return false;
    // A stage starts when the stage changes or EM restarts at step 0 (a new
    // run); other reports of the same stage are iterations or heartbeats.
    const bool starts = !c->started || p.stage != c->stage || (p.step == 0 && c->step != 0);
    const bool new_step = !starts && p.step != c->step;
    c->started = true;
    c->stage = p.stage;
    c->step = p.step;
    if (!starts && !(p.stage == Stage::Em && new_step) && p.stage != Stage::Run) return false;
    const Stage stage = p.stage;
    const int iteration = static_cast<int>(p.step);
    const double ll = p.log_likelihood;
    const auto now = std::chrono::steady_clock::now();
    char buf[160];
    auto close_stage = [&]() {
      if (c->current == nullptr) return;
      const double s = std::chrono::duration<double>(now - c->start).count();
      std::snprintf(buf, sizeof buf, "%s %.3f s", c->current, s);
      if (!c->done.empty()) c->done += ", ";
      c->done += buf;
      if (mode_ == ProgressMode::Lines) {
        std::snprintf(buf, sizeof buf, "%s done in %.3f s", c->current, s);
        show(label + ": " + buf, true);
      }
    };
    if (stage == Stage::Em && iteration > 0) {  // after an EM iteration
      const double s = std::chrono::duration<double>(now - c->start).count();
      std::snprintf(buf, sizeof buf, "EM iteration %d, mean log-likelihood %.4f (%.3f s)", iteration, ll, s);
      // Live: every iteration on one line; lines: every 10th, to keep logs short.
      if (mode_ == ProgressMode::Lines) {
        if (iteration % 10 == 0) show(label + ": " + buf, true);
      } else {
        show(label + ": " + c->done + (c->done.empty() ? "" : "; ") + buf, false);
      }
      return false;
    }
    close_stage();
    if (stage == Stage::Run) {  // a new run of k-means++ + EM starts
      c->current = nullptr;
      if (iteration > 1) std::snprintf(buf, sizeof buf, "run %d (best mean log-likelihood so far %.4f)", iteration, ll);
      else std::snprintf(buf, sizeof buf, "run %d", iteration);
      show(label + ": " + buf, mode_ == ProgressMode::Lines);
      return false;
    }
    c->current = stage == Stage::ModeCount ? "mode count" : stage == Stage::Seeding ? "seeding" : "EM";
    c->start = now;
    const std::string what = stage == Stage::ModeCount ? "mode count (mean shift)..."
                             : stage == Stage::Seeding ? "seeding (k-means++)..."
                                                       : "EM...";
    show(label + ": " + (mode_ == ProgressMode::Live && !c->done.empty() ? c->done + "; " : std::string()) + what,
         mode_ == ProgressMode::Lines);
    return false;
  };
}

std::int64_t unix_ms_now() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

std::string human_bytes(std::uint64_t bytes) {
  char buf[96];
  if (bytes < 1024)
    std::snprintf(buf, sizeof buf, "%llu bytes", static_cast<unsigned long long>(bytes));
  else if (bytes < 1024 * 1024)
    std::snprintf(buf, sizeof buf, "%.1f KiB (%llu bytes)", bytes / 1024.0, static_cast<unsigned long long>(bytes));
  else
    std::snprintf(buf, sizeof buf, "%.2f MiB (%llu bytes)", bytes / 1048576.0, static_cast<unsigned long long>(bytes));
  return buf;
}

int run_guarded(const std::function<int()>& body) {
  try {
    return body();
  } catch (const Error& e) {
    if (e.code() == ErrorCode::Cancelled) {
      std::fprintf(stderr, "sogmm: interrupted: %s; nothing written\n", e.what());
      return kExitInterrupted;
    }
    std::fprintf(stderr, "sogmm: error: %s\n", e.what());
    switch (e.code()) {
      case ErrorCode::InvalidArgument: return kExitUsage;
      case ErrorCode::Io: return kExitIo;
      default: return kExitInvalidData;
    }
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "sogmm: error: out of memory\n");
    return kExitInvalidData;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sogmm: error: %s\n", e.what());
    return kExitInvalidData;
  }
}

}  // namespace sogmm::tools

#include <nlohmann/json.hpp>

namespace sogmm::tools {
void print_evaluation(const Evaluation& e, bool json, const nlohmann::json* extra) {
  const auto& f = e.fit;
  if (json) {
    nlohmann::json j;
    j["n_points"] = f.n_points;
    j["n_components"] = f.gmm.size();
    j["psnr"] = e.psnr.psnr;
    j["psnr_paper"] = e.psnr.psnr_paper;
    j["psnr_data_range"] = e.psnr.data_range;
    j["mre"] = e.reconstruction.mre;
    j["precision"] = e.reconstruction.precision;
    j["recall"] = e.reconstruction.recall;
    j["fscore"] = e.reconstruction.fscore;
    j["model_bytes"] = e.model_bytes;
    j["em_iterations"] = f.em.iterations;
    j["converged"] = f.em.converged;
    j["log_likelihood"] = f.em.log_likelihood;
    // Measured only with --tol-standard-errors > 0 (EmReport::standard_error).
    if (f.em.standard_error > 0) j["log_likelihood_standard_error"] = f.em.standard_error;
    else j["log_likelihood_standard_error"] = nullptr;
    j["n_init"] = f.run_log_likelihoods.size();
    j["run"] = f.run;
    j["run_log_likelihoods"] = f.run_log_likelihoods;
    j["seconds_mode_count"] = f.seconds_mode_count;
    j["seconds_seeding"] = f.seconds_seeding;
    j["seconds_em"] = f.seconds_em;
    j["seconds_total"] = f.seconds_total;
    if (extra != nullptr) j.update(*extra);
    std::printf("%s\n", j.dump().c_str());
    return;
  }
  std::printf("points N            %zu\n", f.n_points);
  std::printf("components M        %zu\n", f.gmm.size());
  std::printf("EM iterations       %d (%s)\n", f.em.iterations, f.em.converged ? "converged" : "not converged");
  std::printf("mean log-likelihood %.4f\n", f.em.log_likelihood);
  if (f.run_log_likelihoods.size() > 1)
    std::printf("runs                %zu, kept run %d (seed + %d)\n", f.run_log_likelihoods.size(), f.run, f.run);
  std::printf("time mode count     %.3f s\n", f.seconds_mode_count);
  std::printf("time seeding        %.3f s\n", f.seconds_seeding);
  std::printf("time EM             %.3f s\n", f.seconds_em);
  std::printf("time total          %.3f s\n", f.seconds_total);
  std::printf("PSNR (honest)       %.2f dB (data range %g)\n", e.psnr.psnr, e.psnr.data_range);
  std::printf("PSNR (paper-compat) %.2f dB (+13.98 dB for the paper's 640x480 canvas)\n", e.psnr.psnr_paper);
  std::printf("MRE (mass-weighted) %.4f m\n", e.reconstruction.mre);
  std::printf("precision / recall  %.3f / %.3f (mass-weighted; authors' naming)\n", e.reconstruction.precision,
              e.reconstruction.recall);
  std::printf("F-score @ 0.01 m    %.3f (mass-weighted)\n", e.reconstruction.fscore);
  std::printf("model bytes (paper) %zu\n", e.model_bytes);
}
}  // namespace sogmm::tools
