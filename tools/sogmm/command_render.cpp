// `sogmm render`: images of what a model predicts: gray, its conditional
// standard deviation, or a side-by-side comparison with a frame.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "cli_common.hpp"
#include "file_util.hpp"
#include "model_io.hpp"
#include "occupancy_slice.hpp"
#include "render.hpp"
#include "sequence.hpp"
#include "sogmm/error.hpp"
#include "sogmm/inference.hpp"

namespace sogmm::tools {

namespace {

struct RenderState {
  std::string model, output, depth, color, trajectory;
  int frame = -1;
  CameraFlags camera;
  DepthOptions depth_options;
  bool compare = false, uncertainty = false, occupancy = false;
  SliceFlags slice;
  int scale = 0;
  double error_max = 0.25, std_max = 0.0, max_mahalanobis = 3.0, surface_sigma = 0.0;
  double data_range = 1.0;  // honest PSNR's peak (--data-range, with --compare)
};

std::vector<float> upscale_values(const std::vector<float>& v, int w, int h, int scale) {
  if (scale == 1) return v;
  std::vector<float> out(static_cast<std::size_t>(w) * scale * h * scale);
  for (int y = 0; y < h * scale; ++y)
    for (int x = 0; x < w * scale; ++x)
      out[static_cast<std::size_t>(y) * w * scale + x] = v[static_cast<std::size_t>(y / scale) * w + x / scale];
  return out;
}

double percentile_99(const std::vector<float>& v) {
  std::vector<float> shown;
  for (float x : v)
    if (x >= 0) shown.push_back(x);
  if (shown.empty()) return 1.0;
  const std::size_t k = std::min(shown.size() - 1, static_cast<std::size_t>(0.99 * shown.size()));
  std::nth_element(shown.begin(), shown.begin() + k, shown.end());
  return std::max(1e-3, static_cast<double>(shown[k]));
}

int run_render(const RenderState& s, const CLI::App& app) {
  check_outputs({{"MODEL", s.model}, {"--depth", s.depth}, {"--color", s.color}, {"--trajectory", s.trajectory},
                 {"--intrinsics", s.camera.intrinsics}},
                {{"-o", s.output}});
  const Model model = load_model(s.model);
  if (s.occupancy) {
    SliceFlags slice = s.slice;
    slice.frame = std::max(s.frame, 0);
    write_occupancy_picture(Map::from_model(model), slice, s.output, s.model);
    return 0;
  }
  Gmm gmm = model.gmm;
  std::string view_note;
  if (!s.trajectory.empty()) {
    const std::vector<Pose> poses = read_trajectory(s.trajectory);
    require(s.frame >= 0 && static_cast<std::size_t>(s.frame) < poses.size(), ErrorCode::InvalidArgument,
            "render: --frame must be in [0, " + std::to_string(poses.size()) + ") for " + s.trajectory);
    gmm = in_camera(model, poses[s.frame]);
    view_note = " seen from pose " + std::to_string(s.frame) + " of " + s.trajectory;
  } else if (key_value(model, "coordinate_frame") == "world") {
    std::fprintf(stderr,
                 "sogmm: note: %s is in world coordinates; rendering from the world origin (give --trajectory FILE "
                 "--frame I to render from a camera of the sequence)\n",
                 s.model.c_str());
  }

  LoadedFrame frame;
  const bool have_depth = !s.depth.empty();
  if (have_depth) frame = s.color.empty() ? load_depth(s.depth) : load_frame(s.depth, s.color);
  Camera camera;
  if (camera_flags_given(s.camera)) {
    camera = have_depth ? resolve_camera(s.camera, frame) : camera_from_flags(s.camera);
  } else {
    camera = camera_for(s.camera, model, s.model);
    if (have_depth)
      require(camera.width == frame.width && camera.height == frame.height, ErrorCode::InvalidData,
              s.depth + ": image is " + std::to_string(frame.width) + "x" + std::to_string(frame.height) +
                  " but the camera stored in " + s.model + " is " + std::to_string(camera.width) + "x" +
                  std::to_string(camera.height) + " (give --intrinsics)");
  }
  const DepthOptions d = depth_options_for(app, s.depth_options, model);
  const Camera dc = decimated(camera, d.decimate);

  if (s.compare) {
    const PointCloud cloud = backproject_nonempty(frame, camera, d, s.depth);
    std::vector<float> gray_truth(cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i) gray_truth[i] = cloud.xyzg[4 * i + 3];
    const std::vector<float> truth = project_to_image(cloud.view(), gray_truth.data(), dc, -1.f);
    const RenderedView est = panel_view(render_at_points(gmm, cloud.view(), dc));
    const PsnrResult p = psnr_images(truth.data(), est.gray.data(), truth.size(), s.data_range);
    const int scale = s.scale > 0 ? s.scale : std::max(1, (320 + dc.width - 1) / dc.width);
    char headline[256];
    std::snprintf(headline, sizeof headline, "PSNR %.2f dB  |  %s: %zu components  |  %s, %dx%d", p.psnr,
                  std::filesystem::path(s.model).filename().string().c_str(), gmm.size(),
                  std::filesystem::path(s.depth).filename().string().c_str(), dc.width, dc.height);
    int w = 0, h = 0;
    const auto img = compose_compare(truth, est.gray, dc.width, dc.height, s.error_max, scale, headline, &w, &h);
    write_png(s.output, w, h, 3, img.data());
    std::printf("Wrote %s (%dx%d): original gray | regressed gray | |error| (0..%g) at %dx%d x%d; PSNR %.2f dB "
                "(paper-compatible %.2f dB) over %zu points.\n",
                s.output.c_str(), w, h, s.error_max, dc.width, dc.height, scale, p.psnr, p.psnr_paper, cloud.size());
    return 0;
  }

  RenderedView view;
  std::string where;
  if (have_depth) {
    const PointCloud cloud = backproject_nonempty(frame, camera, d, s.depth);
    view = panel_view(render_at_points(gmm, cloud.view(), dc));
    where = "at the depth of " + s.depth;
  } else {
    RenderOptions o;
    o.depth_min = d.depth_min;
    o.depth_max = d.depth_max;
    o.max_mahalanobis = s.max_mahalanobis;
    o.surface_sigma = s.surface_sigma;
    view = panel_view(render_expected_surface(gmm, dc, o));
    where = "at the model's expected surface (first surface along each ray)";
  }
  std::size_t shown = 0;
  for (float g : view.gray) shown += g >= 0 ? 1 : 0;
  const int scale = s.scale > 0 ? s.scale : 1;
  int w = 0, h = 0;
  if (s.uncertainty) {
    const double vmax = s.std_max > 0 ? s.std_max : percentile_99(view.stddev);
    const auto img = heat_map_with_bar(view.stddev, view.width, view.height, vmax, scale,
                                       "conditional std of gray", &w, &h);
    write_png(s.output, w, h, 3, img.data());
    std::printf("Wrote %s (%dx%d): conditional standard deviation of gray (colour bar 0..%.3g) %s%s, %zu of %d pixels.\n",
                s.output.c_str(), w, h, vmax, where.c_str(), view_note.c_str(), shown, view.width * view.height);
    return 0;
  }
  w = view.width * scale;
  h = view.height * scale;
  const auto img = gray_to_u8(upscale_values(view.gray, view.width, view.height, scale));
  write_png(s.output, w, h, 1, img.data());
  std::printf("Wrote %s (%dx%d): regressed gray %s%s, %zu of %d pixels (empty pixels are black).\n",
              s.output.c_str(), w, h, where.c_str(), view_note.c_str(), shown, view.width * view.height);
  return 0;
}

}  // namespace

Command add_render_command(CLI::App& root) {
  auto s = std::make_shared<RenderState>();
  CLI::App* app = root.add_subcommand("render", "Render a model's regressed gray (or its uncertainty) as a PNG");
  app->footer(
      "The image has the model's camera decimated by its decimation (or the flags'). Gray is regressed\n"
      "(E[gray | xyz], the paper's conditional) at the 3-D point of each pixel: the ground-truth point with\n"
      "--depth, else the model's expected surface: the nearest mode of the mixture's marginal density along\n"
      "the pixel's ray, the first surface a camera sees (1-D mean shift from every component peak on the\n"
      "ray; pixels whose ray passes outside every component's 3-sigma ellipsoid stay empty/black; with\n"
      "--surface-sigma S only modes where the components' evidence sum exp(-D^2/2) reaches that of one\n"
      "component at S sigma are surfaces, so a ray grazing a tail beyond a silhouette passes on).\n"
      "--compare writes original gray | regressed gray | |error| heat map with colour bar and the PSNR.\n"
      "--uncertainty writes the conditional standard deviation of gray as a heat map with colour bar.\n\n"
      "Examples:\n"
      "  sogmm render frame0.sogmm -o expected.png --scale 4\n"
      "  sogmm render frame0.sogmm --compare --depth ../shared/data/rgbd/livingroom/depth/00000.png \\\n"
      "    --color ../shared/data/rgbd/livingroom/color/00000.jpg -o compare.png\n"
      "  sogmm render room.sogmm --trajectory ../shared/data/rgbd/livingroom/trajectory.log --frame 2 -o view2.png\n"
      "  sogmm render room-map.sogmm --occupancy -o occupancy.png");
  app->add_option("model", s->model, "saved model (.sogmm)")->required();
  app->add_option("-o,--output", s->output, "output PNG")->required();
  app->add_option("--depth", s->depth, "16-bit depth PNG: regress at its points (needed by --compare)");
  app->add_option("--color", s->color, "color image of the frame (needed by --compare)");
  app->add_flag("--compare", s->compare, "side-by-side original | regressed | error picture (needs --depth, --color)");
  add_data_range_flag(*app, s->data_range);
  app->add_flag("--uncertainty", s->uncertainty, "write the conditional standard deviation of gray instead");
  app->add_option("--trajectory", s->trajectory, "Redwood .log poses: render a world-frame model from --frame");
  app->add_option("--frame", s->frame, "pose index in --trajectory (--occupancy: frame of the map, default 0)");
  app->add_flag("--occupancy", s->occupancy,
                "a map: free/occupied/unknown on a horizontal slice beside the expected surface from --frame");
  app->add_option("--slice-axis", s->slice.axis, "--occupancy: the slice's normal, x|y|z (default: the cameras' up)");
  app->add_option("--slice-at", s->slice.height,
                  "--occupancy: the slice's position along --slice-axis, m (default: the cameras' mean height)");
  app->add_option("--cell", s->slice.cell, "--occupancy: slice pixel size, m")->capture_default_str();
  add_camera_flags(*app, s->camera, s->depth_options);
  app->add_option("--scale", s->scale, "integer upscaling of the picture (default 1; --compare: panels >= 320 px)");
  app->add_option("--error-max", s->error_max, "|error| at the top of the colour bar (--compare)")->capture_default_str();
  app->add_option("--std-max", s->std_max, "std at the top of the colour bar (--uncertainty; 0 = 99th percentile)")
      ->capture_default_str();
  app->add_option("--max-mahalanobis", s->max_mahalanobis,
                  "expected surface: empty where the ray is farther than this many sigmas from every component")
      ->capture_default_str();
  app->add_option("--surface-sigma", s->surface_sigma,
                  "expected surface: a mode counts only where the components' evidence reaches one component's at "
                  "this many sigmas (0 = every mode; 2 = the edge of a flat component's disc)")
      ->capture_default_str();
  CLI::App* a = app;
  return {app, [s, a]() {
            require(!(s->compare && s->uncertainty), ErrorCode::InvalidArgument,
                    "render: choose --compare or --uncertainty, not both");
            if (s->compare)
              require(!s->depth.empty() && !s->color.empty(), ErrorCode::InvalidArgument,
                      "render: --compare needs --depth D and --color C");
            require(s->occupancy || s->trajectory.empty() == (s->frame < 0), ErrorCode::InvalidArgument,
                    "render: --trajectory and --frame go together");
            require(!s->occupancy || (!s->compare && !s->uncertainty && s->trajectory.empty() && s->depth.empty()),
                    ErrorCode::InvalidArgument,
                    "render: --occupancy draws a map from its own frames; it takes none of --compare, --uncertainty, "
                    "--trajectory, --depth");
            require(s->scale >= 0 && s->scale <= 16, ErrorCode::InvalidArgument, "render: --scale must be in 1..16");
            require(s->error_max > 0 && s->std_max >= 0 && s->max_mahalanobis > 0 && s->surface_sigma >= 0,
                    ErrorCode::InvalidArgument,
                    "render: --error-max and --max-mahalanobis must be > 0, --std-max and --surface-sigma >= 0");
            return run_render(*s, *a);
          }};
}

}  // namespace sogmm::tools
