// `sogmm demo`: the whole pipeline on a synthetic scene, no data needed.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>

#include <nlohmann/json.hpp>

#include "cli_common.hpp"
#include "file_util.hpp"
#include "sequence.hpp"
#include "sogmm/error.hpp"
#include "synthetic_room.hpp"
#include "synthetic_scene.hpp"

namespace sogmm::tools {

namespace {
// The corner scene with a camera sliding sideways, or (loop) the closed room
// with a camera orbiting back to its start (synthetic_room.hpp).
int write_synthetic_sequence(const std::string& dir, int n, bool loop) {
  namespace fs = std::filesystem;
  if (loop)
    require(n >= 2 && n <= 3600, ErrorCode::InvalidArgument, "demo: --frames must be in 2..3600 with --loop");
  else
    require(n >= 1 && n <= 100, ErrorCode::InvalidArgument, "demo: --frames must be in 1..100");
  std::error_code ec;
  fs::create_directories(fs::path(dir) / "depth", ec);
  fs::create_directories(fs::path(dir) / "color", ec);
  require(fs::is_directory(fs::path(dir) / "depth") && fs::is_directory(fs::path(dir) / "color"), ErrorCode::Io,
          dir + ": cannot create the folder");
  const Camera cam = synthetic_camera();
  std::vector<Pose> poses;
  for (int k = 0; k < n; ++k) {
    const double a = k * 2.0 * M_PI / 180.0;  // yaw about the camera's y axis
    const Pose pose = loop ? room_loop_pose(k, n)
                           : Pose{std::cos(a), 0, std::sin(a), 0.04 * k, 0, 1, 0, 0, -std::sin(a), 0, std::cos(a), 0,
                                  0, 0, 0, 1};
    poses.push_back(pose);
    const LoadedFrame f = loop ? room_frame_at(pose) : synthetic_frame_at(pose);
    char name[32];
    std::snprintf(name, sizeof name, "%05d.png", k);
    write_png16((fs::path(dir) / "depth" / name).string(), f.width, f.height, f.depth.data());
    std::vector<std::uint8_t> gray(f.gray.size());
    for (std::size_t i = 0; i < gray.size(); ++i)
      gray[i] = static_cast<std::uint8_t>(std::lround(std::clamp(f.gray[i], 0.f, 1.f) * 255.f));
    write_png((fs::path(dir) / "color" / name).string(), f.width, f.height, 1, gray.data());
  }
  nlohmann::json j;
  j["width"] = cam.width;
  j["height"] = cam.height;
  j["intrinsic_matrix"] = {cam.fx, 0, 0, 0, cam.fy, 0, cam.cx, cam.cy, 1};
  const std::string text = j.dump(2) + "\n";
  write_file_atomic((fs::path(dir) / "intrinsics.json").string(), text.data(), text.size());
  write_trajectory_log((fs::path(dir) / "trajectory.log").string(), poses);
  std::printf("Wrote %d synthetic frame%s (640x480, depth in mm) to %s: depth/, color/, intrinsics.json, "
              "trajectory.log\n",
              n, n == 1 ? "" : "s", dir.c_str());
  return 0;
}
}  // namespace

Command add_demo_command(CLI::App& root) {
  struct State {
    DepthOptions depth_options;
    FitOptions fit;
    bool json = false;
    std::string write_frame;
    int n_frames = 1;
    bool loop = false;
  };
  auto s = std::make_shared<State>();
  s->depth_options.decimate = 5;
  CLI::App* app = root.add_subcommand(
      "demo", "Fit a synthetic RGB-D scene (walls, floor, sphere; 640x480) and report what happened");
  app->footer(
      "--write-frame DIR writes the synthetic scene as files instead of fitting it: DIR/depth/00000.png\n"
      "(16-bit, millimetres), DIR/color/00000.png (8-bit gray), DIR/intrinsics.json and DIR/trajectory.log\n"
      "(camera-to-world poses); with --frames N, N frames from a camera moving 4 cm right and turning 2\n"
      "degrees per frame. The folder is a sequence for sogmm fit/eval/map --sequence.\n"
      "With --loop the scene is a closed 4 x 4 m room (walls, floor, ceiling, two spheres, two boxes) and\n"
      "the camera orbits its centre once, looking out and 15 degrees down, N frames (default 300) with the\n"
      "last pose equal to the first: a loop for incremental mapping (sogmm map).\n\n"
      "Examples:\n  sogmm demo --bandwidth 0.02 --decimate 5\n  sogmm demo --write-frame /tmp/synth --frames 3\n"
      "  sogmm demo --write-frame /tmp/loop --loop");
  app->add_option("--decimate", s->depth_options.decimate, "integer decimation factor")->capture_default_str();
  add_fit_flags(*app, s->fit);
  app->add_flag("--json", s->json, "print one JSON object");
  app->add_option("--write-frame", s->write_frame, "write the synthetic RGB-D frame(s) to this folder and exit");
  app->add_option("--frames", s->n_frames, "with --write-frame: number of frames (1..100; --loop: 2..3600, default 300)")
      ->capture_default_str();
  app->add_flag("--loop", s->loop, "with --write-frame: the room loop instead of the corner scene");
  CLI::App* a = app;
  return {app, [s, a]() {
            require(!s->loop || !s->write_frame.empty(), ErrorCode::InvalidArgument, "demo: --loop needs --write-frame");
            if (s->loop && a->count("--frames") == 0) s->n_frames = 300;
            if (!s->write_frame.empty()) return write_synthetic_sequence(s->write_frame, s->n_frames, s->loop);
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
