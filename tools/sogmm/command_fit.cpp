// `sogmm fit`: fit one RGB-D frame, or a posed sequence merged in the world
// frame, and save the model as a .sogmm file.
#include <cstdio>
#include <filesystem>
#include <memory>

#include <nlohmann/json.hpp>

#include "cli_common.hpp"
#include "file_util.hpp"
#include "map_run.hpp"
#include "model_io.hpp"
#include "sequence.hpp"
#include "sigint_cancel.hpp"
#include "sogmm/error.hpp"
#include "sogmm/inference.hpp"
#include "sogmm/metadata_string.hpp"

namespace sogmm::tools {

namespace {

struct FitState {
  FrameSource src;
  std::string output;
  CameraFlags camera;
  DepthOptions depth_options;
  FitOptions fit;
  bool json = false, progress = false, quiet = false;
  bool warm_start = false;  ///< sequence: start each frame from the previous frame's model
};

std::string base_name(const std::string& p) { return std::filesystem::path(p).filename().string(); }

std::string fit_kind(const FitOptions& o) {
  char buf[96];
  if (o.n_components > 0)
    std::snprintf(buf, sizeof buf, "fixed K = %zu", o.n_components);
  else
    std::snprintf(buf, sizeof buf, "self-organizing, bandwidth %g", o.bandwidth);
  return buf;
}

struct Totals {
  std::size_t points = 0;
  int iterations = 0;
  double mode = 0, seed = 0, em = 0, total = 0;
  void add(const FitResult& r) {
    points += r.n_points;
    iterations += r.em.iterations;
    mode += r.seconds_mode_count;
    seed += r.seconds_seeding;
    em += r.seconds_em;
    total += r.seconds_total;
  }
  void add(std::size_t n_points, const FitRecord& r, double seconds_total) {
    points += n_points;
    iterations += r.em_iterations;
    mode += r.seconds_mode_count;
    seed += r.seconds_seeding;
    em += r.seconds_em;
    total += seconds_total;
  }
};

void print_summary(const FitState& s, const Model& model, const Totals& t, std::uint64_t file_bytes,
                   const nlohmann::json& frames_json, const std::string& what) {
  const std::size_t m = model.gmm.size();
  const double per_component = m > 0 ? static_cast<double>(file_bytes) / m : 0.0;
  if (s.json) {
    nlohmann::json j;
    j["output"] = s.output;
    j["n_points"] = t.points;
    j["support_size"] = model.gmm.support_size;
    j["n_components"] = m;
    j["em_iterations"] = t.iterations;
    if (frames_json.is_null()) {
      j["converged"] = model.fit.converged;
      j["log_likelihood"] = model.fit.log_likelihood;
      // The regulariser the fit used (spec/format.md 2.4).
      j["reg_covar"] = model.fit.reg_covar;
      if (const std::string* g = find_value(model, kRegCovarGrayKey)) j["reg_covar_gray"] = std::stod(*g);
      if (const std::string* src = find_value(model, kRegCovarSourceKey)) j["reg_covar_source"] = *src;
    } else {
      j["frames"] = frames_json;
    }
    j["seconds_mode_count"] = t.mode;
    j["seconds_seeding"] = t.seed;
    j["seconds_em"] = t.em;
    j["seconds_total"] = t.total;
    j["file_bytes"] = file_bytes;
    j["bytes_per_component"] = per_component;
    j["paper_model_bytes"] = paper_model_bytes(model.gmm);
    std::printf("%s\n", j.dump().c_str());
    return;
  }
  std::printf(
      "%s Time: mode count %.3f s, seeding %.3f s, EM %.3f s, total %.3f s. Wrote %s: %s, %.1f bytes per "
      "component (the paper counts %zu bytes, 60 per component).\n",
      what.c_str(), t.mode, t.seed, t.em, t.total, s.output.c_str(), human_bytes(file_bytes).c_str(), per_component,
      paper_model_bytes(model.gmm));
}

int run_single(const FitState& s) {
  const LoadedFrame frame = load_frame(s.src.depth, s.src.color);
  const Camera camera = resolve_camera(s.camera, frame);
  const PointCloud cloud = backproject_nonempty(frame, camera, s.depth_options, s.src.depth);
  ProgressPrinter progress(progress_mode(s.quiet, s.progress));
  progress.line("fit " + base_name(s.src.depth) + ": " + std::to_string(cloud.size()) + " points (decimated by " +
                std::to_string(s.depth_options.decimate) + ")");
  FitResult r = fit(cloud.view(), s.fit, progress.fit_callback("fit " + base_name(s.src.depth)));
  progress.em_done("fit " + base_name(s.src.depth), r);
  progress.finish();
  // File names need not be UTF-8; metadata strings must be (spec/format.md 4.4).
  std::vector<std::pair<std::string, std::string>> key_values{{"source_depth", to_metadata_string(s.src.depth)},
                                                              {"source_color", to_metadata_string(s.src.color)},
                                                              {"coordinate_frame", "camera"}};
  if (s.fit.n_init > 1) key_values.emplace_back("n_init", std::to_string(s.fit.n_init));
  if (dequantises(s.fit.dequantise_depth, cloud.view())) key_values.emplace_back("dequantise_depth", "1");
  const Model model = make_model(r, s.fit, camera, s.depth_options, std::move(key_values));
  const std::uint64_t bytes = save_model(s.output, model);
  Totals t;
  t.add(r);
  const Camera dc = decimated(camera, s.depth_options.decimate);
  const std::string runs = s.fit.n_init > 1 ? "; best of " + std::to_string(s.fit.n_init) + " runs, seed " +
                                                    std::to_string(model.fit.seed)
                                              : "";
  char what[640];
  std::snprintf(what, sizeof what,
                "Fitted %zu points from %s (decimated by %d to %dx%d) with %zu components (%s) in %d EM iterations "
                "(%s, mean log-likelihood %.4f%s).",
                r.n_points, s.src.depth.c_str(), s.depth_options.decimate, dc.width, dc.height, model.gmm.size(),
                fit_kind(s.fit).c_str(), r.em.iterations, r.em.converged ? "converged" : "not converged",
                r.em.log_likelihood, runs.c_str());
  print_summary(s, model, t, bytes, nlohmann::json(), what);
  return 0;
}

// Append everything: the core Map with novelty and fusion off fits each
// frame on its own, moves it with its pose and merges it (map_run.hpp).
int run_sequence(const FitState& s) {
  const SequenceInput in = resolve_sequence(s.src, s.camera);
  MapOptions options;
  options.novelty = false;
  options.fusion = false;
  options.fit = s.fit;
  options.depth = s.depth_options;
  options.warm_start = s.warm_start;
  Map map(options);
  ProgressPrinter progress(progress_mode(s.quiet, s.progress));
  Totals t;
  nlohmann::json frames_json = nlohmann::json::array();
  std::size_t before = 0;
  run_map_over_sequence(map, in, progress, [&](const MapRunFrame& f) {
    const std::size_t m = f.stats.n_components - before;
    before = f.stats.n_components;
    t.add(f.stats.n_points, f.fit, f.stats.ms_fit / 1000.0);
    progress.em_done(f.label, f.fit.seconds_em, f.fit.em_iterations, f.fit.log_likelihood);
    char buf[256];
    std::snprintf(buf, sizeof buf, "%s: %zu points, %zu components, %d EM iterations, %.2f s; map %zu components",
                  f.label.c_str(), f.stats.n_points, m, f.fit.em_iterations, f.stats.ms_fit / 1000.0,
                  f.stats.n_components);
    progress.line(buf);
    frames_json.push_back({{"frame", f.file.index},
                           {"depth", f.file.depth},
                           {"n_points", f.stats.n_points},
                           {"n_components", m},
                           {"em_iterations", f.fit.em_iterations},
                           {"seconds_total", f.stats.ms_fit / 1000.0}});
  });
  progress.finish();
  const Model model = with_sequence_metadata(map.model(), in);
  const std::uint64_t bytes = save_model(s.output, model);
  const std::string frames = frame_list(in);
  char what[512];
  std::snprintf(what, sizeof what,
                "Fitted %zu frames of %s (frames %s, decimated by %d, %s): %zu points in total, merged in the world "
                "frame of %s into %zu components (support size %llu), %d EM iterations in total.",
                in.selected.size(), s.src.sequence.c_str(), frames.c_str(), s.depth_options.decimate,
                fit_kind(s.fit).c_str(), t.points, s.src.trajectory.c_str(), model.gmm.size(),
                static_cast<unsigned long long>(model.gmm.support_size), t.iterations);
  print_summary(s, model, t, bytes, frames_json, what);
  return 0;
}

}  // namespace

Command add_fit_command(CLI::App& root) {
  auto s = std::make_shared<FitState>();
  CLI::App* app = root.add_subcommand("fit", "Fit an RGB-D frame (or a posed sequence) and save the model (.sogmm)");
  app->footer(
      "Progress goes to stderr (a live line on a terminal, plain lines with --progress, nothing with --quiet);\n"
      "a one-paragraph summary goes to stdout. The model is saved atomically with its metadata (fit\n"
      "parameters, camera, decimation, depth scale and range, producer, creation time).\n"
      "A sequence is DIR/depth/*.png + DIR/color/*.{jpg,png} (paired with each other and with the poses by the\n"
      "frame number of their names, 00012.png: the pose '12 ...'; --pair-by-order: by file order); each frame is fitted,\n"
      "moved to the world frame with its camera-to-world pose from the Redwood .log trajectory and merged.\n\n"
      "Examples:\n"
      "  sogmm fit --depth ../shared/data/rgbd/livingroom/depth/00000.png \\\n"
      "    --color ../shared/data/rgbd/livingroom/color/00000.jpg \\\n"
      "    --intrinsics ../shared/data/rgbd/livingroom/intrinsics.json --decimate 5 --bandwidth 0.02 -o frame0.sogmm\n"
      "  sogmm fit --sequence ../shared/data/rgbd/livingroom \\\n"
      "    --trajectory ../shared/data/rgbd/livingroom/trajectory.log --frames 0:3 --decimate 5 -o room.sogmm");
  add_frame_source_flags(*app, s->src);
  add_camera_flags(*app, s->camera, s->depth_options);
  add_fit_flags(*app, s->fit);
  app->add_option("-o,--output", s->output, "output model file (.sogmm)")->required();
  app->add_flag("--progress", s->progress, "print progress lines on stderr even when it is not a terminal");
  app->add_flag("-q,--quiet", s->quiet, "no progress output");
  app->add_flag("--json", s->json, "print the summary as one JSON object");
  app->add_flag("--warm-start", s->warm_start,
                "with --sequence: start each frame's fit from the previous frame's model moved by the relative pose "
                "(components without support removed, new ones seeded where the frame is poorly explained; needs "
                "--n-init 1)");
  CLI::App* a = app;
  return {app, [s, a]() {
            std::vector<NamedFile> inputs = sequence_inputs(s->src, s->camera);
            inputs.insert(inputs.end(), {{"--depth", s->src.depth}, {"--color", s->src.color}});
            check_outputs(inputs, {{"-o", s->output}});
            const SigintCancel ctrl_c;  // Ctrl-C cancels the fits; the output is written only after them
            const bool single = !s->src.depth.empty() || !s->src.color.empty();
            require(single != !s->src.sequence.empty(), ErrorCode::InvalidArgument,
                    "fit: give --depth D --color C, or --sequence DIR --trajectory FILE");
            if (single) {
              require(!s->src.depth.empty() && !s->src.color.empty(), ErrorCode::InvalidArgument,
                      "fit: --depth and --color go together");
              require(s->src.trajectory.empty() && s->src.frames.empty() && !s->warm_start,
                      ErrorCode::InvalidArgument, "fit: --trajectory, --frames and --warm-start need --sequence");
              return run_single(*s);
            }
            require(!s->src.trajectory.empty(), ErrorCode::InvalidArgument,
                    "fit: --sequence needs --trajectory FILE (camera-to-world poses)");
            (void)a;
            return run_sequence(*s);
          }};
}

}  // namespace sogmm::tools
