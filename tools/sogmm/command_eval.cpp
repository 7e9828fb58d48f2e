// `sogmm eval`: score a model against RGB-D frames. Without MODEL it fits the
// frame first (the original behaviour); with MODEL it evaluates the saved
// model, on one frame or on every frame of a posed sequence.
#include <algorithm>
#include <cmath>
#include <limits>
#include <cstdio>
#include <filesystem>
#include <memory>

#include <nlohmann/json.hpp>

#include "cli_common.hpp"
#include "eval_pixels.hpp"
#include "model_io.hpp"
#include "sequence.hpp"
#include "sogmm/error.hpp"
#include "sogmm/inference.hpp"

namespace sogmm::tools {

namespace {

struct EvalState {
  std::string model;
  FrameSource src;
  CameraFlags camera;
  DepthOptions depth_options;
  FitOptions fit;
  double data_range = 1.0;  // honest PSNR's peak (--data-range)
  double surface_sigma = 0.0;  // per-pixel renders: RenderOptions::surface_sigma (--surface-sigma)
  int frame = -1;           // --frame I of --trajectory (one frame of a world-frame model)
  bool json = false;
};

/// How far (m) behind the observed depth of its pixel a model sample may lie
/// and still count as seen (the first-surface rule of frustum_samples). It
/// must exceed the spread of a visible surface's own samples across the
/// surface (a few standard deviations of its components' thickness, and of
/// the depth noise the fit absorbed), so that the rule never drops a sample
/// of what the frame sees, only samples of surfaces hidden behind it.
constexpr double kOcclusionTolerance = 0.05;

/// Samples of the model that this camera could see: inside its view frustum
/// and, where the frame has a depth at the sample's pixel, not more than
/// kOcclusionTolerance behind it. A depth camera sees only the first surface
/// along each ray; a world-frame model also holds the surfaces behind it
/// (seen from other poses), and its samples there lie far from every point
/// of this frame, so MRE would count occlusion as error. A single frame's own
/// fit has no such samples. Samples in front of the observed depth (model
/// error in free space) and at pixels without depth are kept.
std::vector<float> visible_samples(const Gmm& gmm, std::size_t n, std::uint64_t seed, const Camera& cam,
                                   const DepthOptions& d, const PointsView& frame) {
  // Observed depth per pixel of the (decimated) camera: the nearest point.
  const std::size_t w = static_cast<std::size_t>(cam.width), h = static_cast<std::size_t>(cam.height);
  std::vector<float> observed(w * h, std::numeric_limits<float>::infinity());
  auto pixel = [&](const float* p, std::size_t* at) {
    const double z = p[2];
    if (!(z > 0)) return false;
    const long u = std::lround(cam.fx * p[0] / z + cam.cx), v = std::lround(cam.fy * p[1] / z + cam.cy);
    if (u < 0 || v < 0 || u >= cam.width || v >= cam.height) return false;
    *at = static_cast<std::size_t>(v) * w + static_cast<std::size_t>(u);
    return true;
  };
  for (std::size_t i = 0; i < frame.size; ++i) {
    std::size_t at = 0;
    if (pixel(frame[i], &at)) observed[at] = std::min(observed[at], frame[i][2]);
  }
  std::vector<float> all(4 * n);
  sample(gmm, n, seed, 4, all.data());
  std::vector<float> kept;
  kept.reserve(all.size());
  for (std::size_t i = 0; i < n; ++i) {
    const float* p = all.data() + 4 * i;
    const double z = p[2];
    std::size_t at = 0;
    if (!(z > d.depth_min && z <= d.depth_max) || !pixel(p, &at)) continue;
    if (z > observed[at] + kOcclusionTolerance) continue;  // hidden behind the observed surface
    kept.insert(kept.end(), p, p + 4);
  }
  return kept;
}

struct FrameScore {
  std::size_t frame = 0;
  std::string depth;
  std::size_t n_points = 0;
  PsnrResult psnr;
  ReconstructionResult rec;
  std::size_t n_samples = 0;
  PixelFigures pixels;
};

nlohmann::json to_json(const FrameScore& f) {
  nlohmann::json j = {{"frame", f.frame},         {"depth", f.depth},        {"n_points", f.n_points},
                      {"psnr", f.psnr.psnr},      {"psnr_paper", f.psnr.psnr_paper}, {"psnr_data_range", f.psnr.data_range},
                      {"mre", f.rec.mre},         {"precision", f.rec.precision},
                      {"recall", f.rec.recall},   {"fscore", f.rec.fscore},  {"n_samples", f.n_samples}};
  add_to_json(f.pixels, j);
  return j;
}

// Bandwidth as the user would have typed it: 6 significant digits (0.014,
// not the binary double's 0.013999999999999999).
std::string short_number(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", x);
  return buf;
}

void describe_model(const std::string& path, const Model& m, bool json, nlohmann::json& j) {
  const std::uint64_t bytes = std::filesystem::file_size(path);
  if (json) {
    j["model"] = path;
    j["n_components"] = m.gmm.size();
    j["support_size"] = m.gmm.support_size;
    j["model_bytes"] = paper_model_bytes(m.gmm);
    j["file_bytes"] = bytes;
    return;
  }
  std::string how = "unknown fit";
  if (m.fit.known)
    how = m.fit.n_components_requested > 0 ? "fixed K = " + std::to_string(m.fit.n_components_requested)
                                            : "bandwidth " + short_number(m.fit.bandwidth);
  std::printf("model               %s (%zu components, support size %llu, %s)\n", path.c_str(), m.gmm.size(),
              static_cast<unsigned long long>(m.gmm.support_size), how.c_str());
  std::printf("model bytes (paper) %zu; file %s\n", paper_model_bytes(m.gmm), human_bytes(bytes).c_str());
}

int run_fit_and_eval(const EvalState& s) {
  const LoadedFrame frame = load_frame(s.src.depth, s.src.color);
  const Camera camera = resolve_camera(s.camera, frame);
  const PointCloud cloud = backproject_nonempty(frame, camera, s.depth_options, s.src.depth);
  FitResult fitted = fit(cloud.view(), s.fit);
  const PixelFigures pixels = pixel_figures(fitted.gmm, frame, camera, s.depth_options, s.data_range, s.surface_sigma);
  const Evaluation e =
      evaluate(std::move(fitted), cloud.view(), decimated(camera, s.depth_options.decimate), s.fit.seed, s.data_range);
  nlohmann::json extra;
  add_to_json(pixels, extra);
  print_evaluation(e, s.json, s.json ? &extra : nullptr);
  if (!s.json) print_pixel_figures(pixels);
  return 0;
}

int run_model_frame(const EvalState& s, const CLI::App& app) {
  const Model model = load_model(s.model);
  Gmm gmm = model.gmm;
  if (!s.src.trajectory.empty()) {
    const std::vector<Pose> poses = read_trajectory(s.src.trajectory);
    require(static_cast<std::size_t>(s.frame) < poses.size(), ErrorCode::InvalidArgument,
            "eval: --frame must be in [0, " + std::to_string(poses.size()) + ") for " + s.src.trajectory);
    gmm = in_camera(model, poses[static_cast<std::size_t>(s.frame)]);
  } else {
    // A world-frame model seen from the world origin scores nothing the
    // frame saw: refuse instead of printing meaningless figures.
    require(key_value(model, "coordinate_frame") != "world", ErrorCode::InvalidArgument,
            "eval: " + s.model + " is in world coordinates (a sequence model or map): give --trajectory FILE "
            "--frame I to score it from that frame's camera, or --sequence DIR --trajectory FILE for every frame");
  }
  const LoadedFrame frame = load_frame(s.src.depth, s.src.color);
  Camera camera;
  if (camera_flags_given(s.camera)) {
    camera = resolve_camera(s.camera, frame);
  } else {
    camera = camera_for(s.camera, model, s.model);
    require(camera.width == frame.width && camera.height == frame.height, ErrorCode::InvalidData,
            s.src.depth + ": image is " + std::to_string(frame.width) + "x" + std::to_string(frame.height) +
                " but the camera stored in " + s.model + " is " + std::to_string(camera.width) + "x" +
                std::to_string(camera.height) + " (give --intrinsics)");
  }
  const DepthOptions d = depth_options_for(app, s.depth_options, model);
  const PointCloud cloud = backproject_nonempty(frame, camera, d, s.src.depth);
  const Camera dc = decimated(camera, d.decimate);
  FrameScore f;
  f.depth = s.src.depth;
  f.n_points = cloud.size();
  f.psnr = psnr(gmm, cloud.view(), dc, s.data_range);
  f.rec = reconstruction_metrics(gmm, cloud.view(), 0.01, s.fit.seed);
  f.n_samples = cloud.size();
  f.pixels = pixel_figures(gmm, frame, camera, d, s.data_range, s.surface_sigma);
  nlohmann::json j = to_json(f);
  j.erase("frame");
  describe_model(s.model, model, s.json, j);
  if (s.json) {
    std::printf("%s\n", j.dump().c_str());
    return 0;
  }
  std::printf("frame               %s, decimated by %d -> %zu points\n", s.src.depth.c_str(), d.decimate, f.n_points);
  std::printf("PSNR (honest)       %.2f dB (data range %g), gray regressed at the frame's points\n", f.psnr.psnr,
              f.psnr.data_range);
  std::printf("PSNR (paper-compat) %.2f dB (+13.98 dB for the paper's 640x480 canvas)\n", f.psnr.psnr_paper);
  std::printf("MRE (mass-weighted) %.4f m, over samples of the model\n", f.rec.mre);
  std::printf("precision / recall  %.3f / %.3f (mass-weighted; authors' naming)\n", f.rec.precision, f.rec.recall);
  std::printf("F-score @ 0.01 m    %.3f (mass-weighted)\n", f.rec.fscore);
  print_pixel_figures(f.pixels);
  return 0;
}

// Adds a frame's per-pixel figures / `frames` to the running mean `m`
// (pixel counts are summed).
void add_mean(const PixelFigures& f, std::size_t frames, PixelFigures& m) {
  const double k = 1.0 / static_cast<double>(frames);
  m.decimate = f.decimate;
  for (auto [from, to] : {std::pair{&f.fit_grid, &m.fit_grid}, std::pair{&f.heldout, &m.heldout}}) {
    to->n_observed += from->n_observed;
    to->n_both += from->n_both;
    to->depth_mae += from->depth_mae * k;
    to->empty_share += from->empty_share * k;
    to->psnr += from->psnr * k;
  }
  m.log_likelihood += f.log_likelihood * k;
  m.log_likelihood_heldout += f.log_likelihood_heldout * k;
  m.n_points_heldout += f.n_points_heldout;
}

int run_model_sequence(const EvalState& s, const CLI::App& app) {
  const Model model = load_model(s.model);
  const std::vector<SequenceFrame> frames = list_sequence(s.src.sequence, s.src.pair_by_order);
  const std::vector<std::size_t> selected =
      parse_frame_range(s.src.frames.empty() ? std::string(":") : s.src.frames, frames.size());
  const std::vector<Pose> poses = poses_of_frames(read_trajectory_log(s.src.trajectory), s.src.trajectory, frames,
                                                  selected, s.src.pair_by_order);
  if (key_value(model, "coordinate_frame") == "camera")
    std::fprintf(stderr, "sogmm: note: %s is a single-frame model in its camera's coordinates; it is moved with "
                 "the inverse of each frame's pose as if it were in world coordinates\n", s.model.c_str());
  CameraFlags flags = s.camera;
  const std::string guess = (std::filesystem::path(s.src.sequence) / "intrinsics.json").string();
  if (!camera_flags_given(flags) && !model.camera.known && std::filesystem::is_regular_file(guess))
    flags.intrinsics = guess;
  const DepthOptions d = depth_options_for(app, s.depth_options, model);
  std::vector<FrameScore> scores;
  for (std::size_t k = 0; k < selected.size(); ++k) {
    const std::size_t i = selected[k];
    const SequenceFrame& f = frames[i];
    const LoadedFrame frame = load_frame(f.depth, f.color);
    const Camera camera = camera_flags_given(flags) ? resolve_camera(flags, frame) : camera_for(flags, model, s.model);
    require(camera.width == frame.width && camera.height == frame.height, ErrorCode::InvalidData,
            f.depth + ": image size differs from the camera (give --intrinsics)");
    const PointCloud cloud = backproject_nonempty(frame, camera, d, f.depth);
    const Camera dc = decimated(camera, d.decimate);
    const Gmm local = in_camera(model, poses[k]);
    FrameScore sc;
    sc.frame = i;
    sc.depth = f.depth;
    sc.n_points = cloud.size();
    sc.psnr = psnr(local, cloud.view(), dc, s.data_range);
    sc.pixels = pixel_figures(local, frame, camera, d, s.data_range, s.surface_sigma);
    // As many samples as the model was fitted on, kept where this camera sees.
    const std::size_t n = static_cast<std::size_t>(
        std::min<std::uint64_t>(std::max<std::uint64_t>(model.gmm.support_size, cloud.size()), 4000000));
    const std::vector<float> kept = visible_samples(local, n, s.fit.seed + i, dc, d, cloud.view());
    sc.n_samples = kept.size() / 4;
    if (sc.n_samples > 0) {
      sc.rec = compare_clouds(kept.data(), sc.n_samples, 4, cloud.view(), 0.01);
    } else {
      sc.rec.mre = std::nan("");
    }
    scores.push_back(sc);
  }
  FrameScore mean;
  for (const FrameScore& f : scores) {
    mean.n_points += f.n_points;
    mean.n_samples += f.n_samples;
    mean.psnr.psnr += f.psnr.psnr / scores.size();
    mean.psnr.psnr_paper += f.psnr.psnr_paper / scores.size();
    mean.rec.mre += f.rec.mre / scores.size();
    mean.rec.precision += f.rec.precision / scores.size();
    mean.rec.recall += f.rec.recall / scores.size();
    mean.rec.fscore += f.rec.fscore / scores.size();
    add_mean(f.pixels, scores.size(), mean.pixels);
  }
  nlohmann::json j;
  describe_model(s.model, model, s.json, j);
  if (s.json) {
    j["frames"] = nlohmann::json::array();
    for (const FrameScore& f : scores) j["frames"].push_back(to_json(f));
    nlohmann::json m = to_json(mean);
    m.erase("frame");
    m.erase("depth");
    j["mean"] = m;
    std::printf("%s\n", j.dump().c_str());
    return 0;
  }
  std::printf("frames of %s, decimated by %d; model moved into each camera with the inverse pose;\n"
              "MRE/F-score are mass-weighted: over the samples each camera could see (n_samples: in view, not "
              "hidden behind the frame's depth);\n"
              "per pixel: the rendered first surface vs the frame on the fitting grid (d = %d) and held out "
              "(d = %d minus d = %d)\n",
              s.src.sequence.c_str(), d.decimate, d.decimate, d.decimate + 1, d.decimate);
  std::printf("%-6s %-12s %8s %9s %9s %8s %7s %9s | %8s %6s %7s | %8s %6s %7s\n", "frame", "file", "points",
              "PSNR dB", "paper dB", "MRE m", "F@1cm", "samples", "MAE mm", "empty", "pix dB", "MAE mm", "empty",
              "pix dB");
  const auto row = [](const char* a, const std::string& b, const FrameScore& f) {
    std::printf("%-6s %-12s %8zu %9.2f %9.2f %8.4f %7.3f %9zu | %8.2f %5.1f%% %7.2f | %8.2f %5.1f%% %7.2f\n", a,
                b.c_str(), f.n_points, f.psnr.psnr, f.psnr.psnr_paper, f.rec.mre, f.rec.fscore, f.n_samples,
                1000 * f.pixels.fit_grid.depth_mae, 100 * f.pixels.fit_grid.empty_share, f.pixels.fit_grid.psnr,
                1000 * f.pixels.heldout.depth_mae, 100 * f.pixels.heldout.empty_share, f.pixels.heldout.psnr);
  };
  for (const FrameScore& f : scores)
    row(std::to_string(f.frame).c_str(), std::filesystem::path(f.depth).filename().string(), f);
  row("mean", "(sum pts)", mean);
  return 0;
}

}  // namespace

Command add_eval_command(CLI::App& root) {
  auto s = std::make_shared<EvalState>();
  CLI::App* app = root.add_subcommand(
      "eval", "Report PSNR, MRE, F-score and size of a saved model (MODEL) or of a fresh fit of one frame");
  app->footer(
      "Without MODEL the frame is fitted first (fit flags apply) and timings are reported. With MODEL the\n"
      "saved model is scored; its camera, decimation and depth range are taken from the file unless given.\n"
      "With --sequence DIR --trajectory FILE a world-frame model (sogmm fit --sequence) is moved into each\n"
      "frame's camera with the inverse pose and scored per frame; MRE and F-score use the model's samples\n"
      "that the camera could see: in its frustum and not more than 5 cm behind the frame's depth at\n"
      "their pixel (a depth camera sees the first surface only): these are mass-weighted figures.\n"
      "A world-frame model scored on one frame needs --trajectory FILE --frame I (its camera's pose).\n"
      "Per visible pixel: the model is rendered from the frame's camera (the first surface along each\n"
      "pixel's ray, as `sogmm render`) and compared with the frame: depth_mae (metres, over pixels valid in\n"
      "both), empty_share (share of the frame's valid pixels the rendering leaves empty) and pixel_psnr (gray,\n"
      "same pixels), on the fitting grid (decimation d) and on the held-out grid: the pixels of the d + 1\n"
      "grid that are not on the d grid (*_heldout), with the mean log-likelihood per point on both grids.\n\n"
      "Examples:\n"
      "  sogmm eval --depth ../shared/data/rgbd/livingroom/depth/00000.png \\\n"
      "    --color ../shared/data/rgbd/livingroom/color/00000.jpg \\\n"
      "    --intrinsics ../shared/data/rgbd/livingroom/intrinsics.json --decimate 5 --bandwidth 0.02\n"
      "  sogmm eval frame0.sogmm --depth ../shared/data/rgbd/livingroom/depth/00000.png \\\n"
      "    --color ../shared/data/rgbd/livingroom/color/00000.jpg --json\n"
      "  sogmm eval room.sogmm --sequence ../shared/data/rgbd/livingroom \\\n"
      "    --trajectory ../shared/data/rgbd/livingroom/trajectory.log --frames 0:3");
  app->add_option("model", s->model, "saved model (.sogmm) to evaluate; omit to fit the frame first");
  add_frame_source_flags(*app, s->src, "with MODEL: ");
  add_camera_flags(*app, s->camera, s->depth_options);
  add_fit_flags(*app, s->fit);
  add_data_range_flag(*app, s->data_range);
  app->add_option("--surface-sigma", s->surface_sigma,
                  "per-pixel figures: render with sogmm render's --surface-sigma (0 = every mode is a surface)")
      ->capture_default_str();
  app->add_option("--frame", s->frame,
                  "with MODEL, --depth/--color and --trajectory: the pose index of the frame (world-frame model)");
  app->add_flag("--json", s->json, "print one JSON object");
  CLI::App* a = app;
  return {app, [s, a]() {
            require(std::isfinite(s->surface_sigma) && s->surface_sigma >= 0, ErrorCode::InvalidArgument,
                    "eval: --surface-sigma must be finite and >= 0");
            if (s->model.empty()) {
              require(s->src.sequence.empty() && s->src.trajectory.empty() && s->src.frames.empty(), ErrorCode::InvalidArgument,
                      "eval: --sequence needs a MODEL (fit one with: sogmm fit --sequence DIR --trajectory FILE -o M)");
              require(!s->src.depth.empty() && !s->src.color.empty(), ErrorCode::InvalidArgument,
                      "eval: give MODEL, or --depth D --color C to fit and evaluate the frame");
              return run_fit_and_eval(*s);
            }
            require(!any_given(*a, {"--bandwidth", "--components", "--tol", "--max-iter", "--reg-covar", "--n-init",
                                     "--truncate", "--em-acceleration", "--tol-standard-errors"}),
                    ErrorCode::InvalidArgument,
                    "eval: --bandwidth/--components/--tol/--max-iter/--reg-covar/--n-init/--truncate/--em-acceleration/"
                    "--tol-standard-errors apply only "
                    "without MODEL");
            if (!s->src.sequence.empty()) {
              require(!s->src.trajectory.empty(), ErrorCode::InvalidArgument, "eval: --sequence needs --trajectory FILE");
              require(s->src.depth.empty() && s->src.color.empty(), ErrorCode::InvalidArgument,
                      "eval: give --sequence or --depth/--color, not both");
              return run_model_sequence(*s, *a);
            }
            require(s->src.frames.empty(), ErrorCode::InvalidArgument, "eval: --frames needs --sequence");
            require(s->src.trajectory.empty() == (s->frame < 0), ErrorCode::InvalidArgument,
                    "eval: with --depth/--color, --trajectory FILE and --frame I go together");
            require(!s->src.depth.empty() && !s->src.color.empty(), ErrorCode::InvalidArgument,
                    "eval: give --depth D --color C (or --sequence DIR --trajectory FILE) to evaluate " + s->model);
            return run_model_frame(*s, *a);
          }};
}

}  // namespace sogmm::tools
