// `sogmm eval`: fit one RGB-D frame and score the model against it.
#include <memory>

#include "cli_common.hpp"
#include "sogmm/error.hpp"

namespace sogmm::tools {

Command add_eval_command(CLI::App& root) {
  struct State {
    std::string depth, color;
    CameraFlags camera;
    DepthOptions depth_options;
    FitOptions fit;
    bool json = false;
  };
  auto s = std::make_shared<State>();
  CLI::App* app = root.add_subcommand("eval", "Fit one RGB-D frame and report PSNR, MRE, F-score, size and timings");
  app->footer(
      "Example:\n  sogmm eval --depth ../shared/data/rgbd/livingroom/depth/00000.png \\\n"
      "    --color ../shared/data/rgbd/livingroom/color/00000.jpg \\\n"
      "    --intrinsics ../shared/data/rgbd/livingroom/intrinsics.json --decimate 5 --bandwidth 0.02");
  app->add_option("--depth", s->depth, "16-bit depth PNG")->required();
  app->add_option("--color", s->color, "color or gray image (PNG/JPEG), registered to the depth")->required();
  add_camera_flags(*app, s->camera, s->depth_options);
  add_fit_flags(*app, s->fit);
  app->add_flag("--json", s->json, "print one JSON object");
  return {app, [s]() {
            const LoadedFrame frame = load_frame(s->depth, s->color);
            const Camera camera = resolve_camera(s->camera, frame);
            const PointCloud cloud = backproject(frame.view(camera), s->depth_options);
            require(cloud.size() > 0, ErrorCode::InvalidData,
                    s->depth + ": no valid depth pixel in (" + std::to_string(s->depth_options.depth_min) + ", " +
                        std::to_string(s->depth_options.depth_max) + "] m (check --depth-scale)");
            FitResult fitted = fit(cloud.view(), s->fit);
            const Evaluation e =
                evaluate(std::move(fitted), cloud.view(), decimated(camera, s->depth_options.decimate), s->fit.seed);
            print_evaluation(e, s->json);
            return 0;
          }};
}

}  // namespace sogmm::tools
