// `sogmm map DIR [--trajectory LOG]`: build an incremental world map of an
// RGB-D sequence (posed, or posed by registration to the map) with the core's
// Map (novelty test, batched fits, optional fusion; sogmm/map.hpp), with live
// progress, a per-frame CSV and a plot.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>

#include <nlohmann/json.hpp>

#include "cli_common.hpp"
#include "file_util.hpp"
#include "map_deltas.hpp"
#include "map_run.hpp"
#include "model_io.hpp"
#include "sogmm/error.hpp"
#include "svg_plot.hpp"

namespace sogmm::tools {

namespace {

struct MapState {
  FrameSource src;
  std::string output, csv, plot, trajectory_out, deltas;
  CameraFlags camera;
  MapOptions options;
  RegistrationOptions registration;  // tracking, without --trajectory
  TrackingOptions tracking;
  bool no_odometry = false;
  std::string fusion = "off";
  bool no_novelty = false, refine_poses = false;
  bool json = false, progress = false, quiet = false;
};

// Where --csv / --plot go when not given: next to the map, other extension.
std::string beside(const std::string& output, const char* ext) {
  return std::filesystem::path(output).replace_extension(ext).string();
}

struct Row {
  std::size_t frame, points, novel, components, pending;
  bool flushed;
  double ms_novelty, ms_fit, ms_merge;
  std::size_t replaced;  // components a revisit refit replaced
  // How the pose came: "given" (--trajectory), "first" (the map's first
  // frame, at the identity), "registered" (tracking: the map registration)
  // or "odometry" (tracking: the registration to the last frame, which the
  // map registration did not contradict), with the map registration's
  // fitness (empty when not registered).
  const char* pose_source;
  double inlier_ratio, registration_ll;
};

std::string csv_text(const std::vector<Row>& rows) {
  std::string out =
      "frame,points,novel_points,components,pending,flushed,ms_novelty,ms_fit,ms_merge,replaced,pose,inlier_ratio,"
      "registration_ll\n";
  char buf[320];
  for (const Row& r : rows) {
    std::snprintf(buf, sizeof buf, "%zu,%zu,%zu,%zu,%zu,%d,%.3f,%.3f,%.3f,%zu,%s,", r.frame, r.points, r.novel,
                  r.components, r.pending, r.flushed ? 1 : 0, r.ms_novelty, r.ms_fit, r.ms_merge, r.replaced,
                  r.pose_source);
    out += buf;
    if (std::string(r.pose_source) == "registered" || std::string(r.pose_source) == "odometry") {
      std::snprintf(buf, sizeof buf, "%.4f,%.4f", r.inlier_ratio, r.registration_ll);
      out += buf;
    } else {
      out += ",";
    }
    out += "\n";
  }
  return out;
}

std::string plot_text(const std::vector<Row>& rows, const std::string& title) {
  std::vector<double> x, comps, nov, fit, merge, total;
  for (const Row& r : rows) {
    x.push_back(static_cast<double>(r.frame));
    comps.push_back(static_cast<double>(r.components));
    nov.push_back(r.ms_novelty);
    fit.push_back(r.ms_fit);
    merge.push_back(r.ms_merge);
    total.push_back(r.ms_novelty + r.ms_fit + r.ms_merge);
  }
  return svg_line_charts(x, "frame",
                         {{title + ": map components", "components", {{"components", "#1f77b4", comps}}},
                          {"time per insert",
                           "ms",
                           {{"total", "#333333", total},
                            {"novelty", "#2ca02c", nov},
                            {"fit", "#d62728", fit},
                            {"merge", "#9467bd", merge}}}});
}

int run_map(MapState& s) {
  const std::string csv = s.csv.empty() ? beside(s.output, ".csv") : s.csv;
  const std::string plot = s.plot.empty() ? beside(s.output, ".svg") : s.plot;
  std::vector<NamedFile> outputs = {{"-o", s.output}, {"--csv", csv}, {"--plot", plot}};
  if (!s.trajectory_out.empty()) outputs.push_back({"--trajectory-out", s.trajectory_out});
  check_outputs(sequence_inputs(s.src, s.camera), outputs);
  s.options.novelty = !s.no_novelty;
  s.tracking.odometry = !s.no_odometry;
  validate(s.tracking);
  validate(s.registration);  // before any file is read, so an error names the option, not a frame
  s.options.fusion = s.fusion != "off";
  s.options.fusion_method = s.fusion == "kl" ? FusionMethod::KL : FusionMethod::Hellinger;
  Map map(s.options);  // checks the options before any file is read
  if (s.refine_poses && s.src.trajectory.empty())
    throw Error(ErrorCode::InvalidArgument, "--refine-poses refines the poses of --trajectory: give one");
  SequenceInput in = resolve_sequence(s.src, s.camera);
  in.refine_poses = s.refine_poses;
  ProgressPrinter progress(progress_mode(s.quiet, s.progress));
  std::vector<Row> rows;
  std::size_t points = 0, novel = 0;
  double ms_novelty = 0, ms_fit = 0, ms_merge = 0;
  std::vector<Pose> poses_used;
  std::size_t skipped = 0, by_odometry = 0;
  DeltaWriter deltas(s.deltas);
  run_map_over_sequence(
      map, in, progress,
      [&](const MapRunFrame& f) {
    if (f.skipped) {
      ++skipped;
      return;
    }
    poses_used.push_back(f.pose);
    if (f.source == PoseSource::Odometry) ++by_odometry;
    const FrameStats& st = f.stats;
    if (st.flushed) deltas.write(map);
    const std::size_t pending = map.pending();
    const bool given = !in.poses.empty() && !in.refine_poses;
    rows.push_back({f.file.index, st.n_points, st.n_novel, st.n_components, pending, st.flushed, st.ms_novelty,
                    st.ms_fit, st.ms_merge, st.n_replaced,
                    given ? "given" : source_name(f.source), f.registration.inlier_ratio,
                    f.registration.log_likelihood});
    points += st.n_points;
    novel += st.n_novel;
    ms_novelty += st.ms_novelty;
    ms_fit += st.ms_fit;
    ms_merge += st.ms_merge;
    char buf[320];
    std::snprintf(buf, sizeof buf,
                  "%s: %zu points, %zu novel, %zu pending; map %zu components (novelty %.1f ms, fit %.1f ms, merge "
                  "%.1f ms)",
                  f.label.c_str(), st.n_points, st.n_novel, pending, st.n_components, st.ms_novelty, st.ms_fit,
                  st.ms_merge);
    progress.status(buf);
      },
      s.registration, s.tracking);
  const auto t0 = std::chrono::steady_clock::now();
  const std::size_t added = map.flush(progress.fit_callback("final flush"));
  const double ms_flush = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  deltas.write(map);  // the final flush and the frames since the last delta
  progress.finish();
  if (!s.trajectory_out.empty()) write_trajectory_log(s.trajectory_out, poses_used);
  const Model model = with_sequence_metadata(map.to_model(), in);
  // The map's component precision also selects the quantized arrays
  // (spec/format.md 5.7) at the same bound.
  format::WriteOptions write;
  write.component_precision = s.options.component_precision;
  const std::uint64_t bytes = save_model(s.output, model, write);
  const std::string frames = frame_list(in);
  const std::string csv_body = csv_text(rows);
  write_file_atomic(csv, csv_body.data(), csv_body.size());
  const std::string svg = plot_text(rows, std::filesystem::path(s.src.sequence).filename().string());
  write_file_atomic(plot, svg.data(), svg.size());
  const MapStats st = map.stats();
  if (s.json) {
    nlohmann::json j;
    j["output"] = s.output;
    j["csv"] = csv;
    j["plot"] = plot;
    j["n_frames"] = rows.size();
    j["n_skipped"] = skipped;
    j["n_odometry"] = by_odometry;
    j["n_points"] = points;
    j["n_novel"] = novel;
    j["n_components"] = model.gmm.size();
    j["support_size"] = model.gmm.support_size;
    j["n_flushes"] = st.n_flushes;
    j["n_fused"] = st.n_fused;
    j["n_refits"] = st.n_refits;
    j["final_flush_components"] = added;
    j["ms_novelty"] = ms_novelty;
    j["ms_fit"] = ms_fit;
    j["ms_merge"] = ms_merge;
    j["ms_final_flush"] = ms_flush;
    j["file_bytes"] = bytes;
    if (!s.deltas.empty()) {
      j["n_deltas"] = deltas.count();
      j["delta_bytes"] = deltas.bytes();
    }
    std::printf("%s\n", j.dump().c_str());
    return 0;
  }
  std::printf(
      "Mapped %zu frames of %s (frames %s): %zu points, %zu novel (%.1f%%), %llu fits (%llu revisit refits), %llu components fused; the "
      "map has %zu components (support size %llu). Time: novelty %.2f s, fit %.2f s, merge %.2f s, final flush %.2f "
      "s. Wrote %s (%s), %s and %s.\n",
      rows.size(), s.src.sequence.c_str(), frames.c_str(), points, novel, points ? 100.0 * novel / points : 0.0,
      static_cast<unsigned long long>(st.n_flushes), static_cast<unsigned long long>(st.n_refits),
      static_cast<unsigned long long>(st.n_fused), model.gmm.size(),
      static_cast<unsigned long long>(model.gmm.support_size), ms_novelty / 1000, ms_fit / 1000, ms_merge / 1000,
      ms_flush / 1000, s.output.c_str(), human_bytes(bytes).c_str(), csv.c_str(), plot.c_str());
  return 0;
}

}  // namespace

Command add_map_command(CLI::App& root) {
  auto s = std::make_shared<MapState>();
  s->options.depth.decimate = 5;
  CLI::App* app = root.add_subcommand(
      "map", "Build an incremental world map of a posed RGB-D sequence (only new parts of each frame are fitted)");
  app->footer(
      "Each frame's points are moved to the world with the frame's camera-to-world pose and scored with the\n"
      "3-D log-likelihood of the map's local components; points below --threshold are novel. Once --batch\n"
      "novel points are pending they are fitted (the usual self-organizing fit at --bandwidth times a scale\n"
      "from --novelty-bandwidth-scale) and merged. A frame whose explained points have --revisit-refit-ratio\n"
      "times as many modes as the map has components on its surfaces refits them (its points plus samples\n"
      "of what it does not see replace them). With --fusion new\n"
      "components close to existing ones (Hellinger or symmetric KL distance below --fusion-threshold) are\n"
      "merged into them. --no-novelty fits every frame whole (the append-everything map of sogmm fit\n"
      "--sequence). Progress goes to stderr (a live line on a terminal, lines with --progress); the per-frame\n"
      "CSV (frame,points,novel_points,components,pending,flushed,ms_novelty,ms_fit,ms_merge,replaced,pose,\n"
      "inlier_ratio,registration_ll) and an SVG plot\n"
      "of components and time against frame go next to the map unless --csv/--plot say where.\n"
      "Evaluate the result with sogmm eval MAP --sequence DIR --trajectory LOG.\n\n"
      "Examples:\n"
      "  sogmm demo --write-frame /tmp/loop --loop\n"
      "  sogmm map /tmp/loop --trajectory /tmp/loop/trajectory.log -o loop.sogmm\n"
      "  sogmm map /tmp/loop -o loop.sogmm --trajectory-out /tmp/loop/estimated.log   (poses from the map)\n"
      "  sogmm map ../shared/data/rgbd/livingroom --trajectory ../shared/data/rgbd/livingroom/trajectory.log \\\n"
      "    --frames 0:3 --fusion hellinger -o room.sogmm");
  app->add_option("DIR", s->src.sequence, "sequence folder: depth/*.png and color/*.{jpg,png}")->required();
  app->add_option("--trajectory", s->src.trajectory,
                  "Redwood .log camera-to-world poses (default: estimate each frame's pose by registering it to the "
                  "map from a constant-velocity guess; frames that fail are skipped with a warning)");
  app->add_option("--trajectory-out", s->trajectory_out,
                  "write the poses of the inserted frames (given or estimated) as a Redwood .log");
  app->add_flag("--refine-poses", s->refine_poses,
                "with --trajectory: register each frame to the map from its given pose (e.g. odometry) and insert\n"
                "it at the pose found; a frame that does not register is skipped with a warning");
  app->add_flag("--registration-gray,!--no-registration-gray", s->registration.use_gray,
                "without --trajectory or with --refine-poses: register with gray too (the 4-D density; the default,\n"
                "SOGMM_OPT_REGISTRATION_USE_GRAY), which holds the pose where the geometry alone lets a frame slide\n"
                "(a wall, a floor); --no-registration-gray: the geometry alone (and no odometry)");
  app->add_option("--registration-depth-noise", s->registration.depth_noise,
                  "without --trajectory or with --refine-poses: k of the frames' depth noise sigma_z = k z^2 (1/m),\n"
                  "added along each point's ray to the map's components when registering "
                  "(SOGMM_OPT_REGISTRATION_DEPTH_NOISE; 0: off)")
      ->capture_default_str();
  app->add_flag("--no-odometry", s->no_odometry,
                "tracking: insert only frames whose map registration converged (SOGMM_OPT_TRACKING_ODOMETRY 0); by\n"
                "default a frame the map does not accept is registered to the last inserted frame too and inserted\n"
                "when the two poses agree or the map has too few inliers to judge");
  app->add_option("--odometry-max-disagreement", s->tracking.max_disagreement,
                  "tracking: largest RMS distance (m) between a frame's points at the map's and the odometry's pose\n"
                  "for the two to agree (SOGMM_OPT_TRACKING_MAX_DISAGREEMENT)")
      ->capture_default_str();
  app->add_option("--frames", s->src.frames, "I, A:B (B excluded) or A:B:STEP; default all");
  add_pair_by_order_flag(*app, s->src.pair_by_order);
  add_camera_flags(*app, s->camera, s->options.depth);
  add_fit_flags(*app, s->options.fit);
  app->add_option("--threshold", s->options.novelty_threshold,
                  "novelty threshold (nats): points whose 3-D log-likelihood is below it are new")
      ->capture_default_str();
  app->add_option("--batch", s->options.batch_size, "novel points that trigger a fit")->capture_default_str();
  app->add_option("--novelty-bandwidth-scale", s->options.novelty_bandwidth_scale,
                  "s in (0, 1]: a batch of novel points is fitted with --bandwidth times s + (1 - s) h^2, h the share of "
                  "its point pairs from one frame (1 for one frame); a revisit refit with s (--no-novelty: the bandwidth)")
      ->capture_default_str();
  app->add_option("--revisit-refit-ratio", s->options.revisit_refit_ratio,
                  "refit what a frame sees when its explained points have this many times as many modes as the "
                  "map has components there, 0 or >= 1 (0: off)")
      ->capture_default_str();
  app->add_option("--component-precision", s->options.component_precision,
                  "round each fitted component so that it moves by at most this many of its standard deviations "
                  "(zero low bits that deltas compress away) and store the map file's components as integer codes "
                  "within the same bound (spec/format.md 5.7, format 1.4), in [0, 0.5] (0: full float32)")
      ->capture_default_str();
  app->add_option("--free-space-carve", s->options.free_space_carve,
                  "reshape a map component when this share of its samples lies where a frame sees past it, in "
                  "[0, 0.5] (0: off)")
      ->capture_default_str();
  app->add_flag("--no-novelty", s->no_novelty, "every point is new: fit each frame whole (append everything)");
  app->add_option("--fusion", s->fusion, "fuse close components: off, hellinger or kl")
      ->capture_default_str()
      ->check(CLI::IsMember({"off", "hellinger", "kl"}));
  app->add_option("--fusion-threshold", s->options.fusion_threshold,
                  "fuse below this distance (Hellinger in [0, 1]; KL in nats)")
      ->capture_default_str();
  app->add_option("-o,--output", s->output, "output map file (.sogmm, world frame)")->required();
  app->add_option("--deltas", s->deltas,
                  "write a map delta (spec/format.md 2.5) into this folder after every insert that fitted and at "
                  "the end, named by revision so that they sort (rebuild with sogmm apply-deltas)");
  app->add_option("--csv", s->csv, "per-frame CSV (default: OUTPUT with .csv)");
  app->add_option("--plot", s->plot, "SVG plot of components and time per frame (default: OUTPUT with .svg)");
  app->add_flag("--progress", s->progress, "print progress lines on stderr even when it is not a terminal");
  app->add_flag("-q,--quiet", s->quiet, "no progress output");
  app->add_flag("--json", s->json, "print the summary as one JSON object");
  return {app, [s]() { return run_map(*s); }};
}

}  // namespace sogmm::tools
