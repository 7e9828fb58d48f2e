// `sogmm demo`: the whole pipeline on a synthetic scene, no data needed.
#include <memory>

#include "cli_common.hpp"
#include "synthetic_scene.hpp"

namespace sogmm::tools {

Command add_demo_command(CLI::App& root) {
  struct State {
    DepthOptions depth_options;
    FitOptions fit;
    bool json = false;
  };
  auto s = std::make_shared<State>();
  s->depth_options.decimate = 5;
  CLI::App* app = root.add_subcommand(
      "demo", "Fit a synthetic RGB-D scene (walls, floor, sphere; 640x480) and report what happened");
  app->footer("Example:\n  sogmm demo --bandwidth 0.02 --decimate 5");
  app->add_option("--decimate", s->depth_options.decimate, "integer decimation factor")->capture_default_str();
  add_fit_flags(*app, s->fit);
  app->add_flag("--json", s->json, "print one JSON object");
  return {app, [s]() {
            const LoadedFrame frame = synthetic_frame();
            const Camera camera = synthetic_camera();
            s->depth_options.depth_max = 3.0;
            const PointCloud cloud = backproject(frame.view(camera), s->depth_options);
            if (!s->json)
              std::printf("synthetic scene: 640x480, decimated by %d -> %zu points\n", s->depth_options.decimate,
                          cloud.size());
            FitResult fitted = fit(cloud.view(), s->fit);
            const Evaluation e =
                evaluate(std::move(fitted), cloud.view(), decimated(camera, s->depth_options.decimate), s->fit.seed);
            print_evaluation(e, s->json);
            return 0;
          }};
}

}  // namespace sogmm::tools
