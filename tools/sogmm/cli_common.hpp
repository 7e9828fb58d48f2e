// Pieces shared by the `sogmm` subcommands: camera flags, evaluation, errors.
#pragma once

#include <functional>
#include <string>

#include <CLI/CLI.hpp>

#include "image_io.hpp"
#include "sogmm/camera.hpp"
#include "sogmm/fit.hpp"
#include "sogmm/metrics.hpp"

namespace sogmm::tools {

/// Exit codes of every sogmm tool.
enum ExitCode { kExitOk = 0, kExitUsage = 2, kExitInvalidData = 3, kExitIo = 4 };

/// Camera given on the command line: --intrinsics FILE, or all of
/// --width --height --fx --fy --cx --cy.
struct CameraFlags {
  std::string intrinsics;
  int width = 0, height = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;
};
void add_camera_flags(CLI::App& app, CameraFlags& camera, DepthOptions& depth);
/// The camera from the flags; checks that it matches the frame size.
Camera resolve_camera(const CameraFlags& flags, const LoadedFrame& frame);

/// Model-selection flags: --bandwidth S | --components K, --seed, --threads.
void add_fit_flags(CLI::App& app, FitOptions& options);

/// Everything `sogmm eval` reports about one fit.
struct Evaluation {
  FitResult fit;
  PsnrResult psnr;
  ReconstructionResult reconstruction;
  std::size_t model_bytes = 0;
};
/// Evaluates a model against the cloud it came from (camera = decimated camera).
Evaluation evaluate(FitResult fit, const PointsView& truth, const Camera& decimated_camera, std::uint64_t seed);

/// Runs `body`, turning sogmm::Error and other exceptions into a one-line
/// message on stderr ("sogmm: error: ...") and the documented exit code.
int run_guarded(const std::function<int()>& body);

}  // namespace sogmm::tools

namespace sogmm::tools {
/// Prints an evaluation as a human table, or with `json` as one JSON object
/// with keys n_points, n_components, psnr, psnr_paper, mre, precision, recall,
/// fscore, model_bytes, em_iterations, converged, log_likelihood,
/// seconds_mode_count, seconds_seeding, seconds_em, seconds_total.
void print_evaluation(const Evaluation& e, bool json);

/// A subcommand: its CLI11 parser and what to run when it is chosen.
struct Command {
  CLI::App* app = nullptr;
  std::function<int()> run;
};
Command add_demo_command(CLI::App& root);
Command add_eval_command(CLI::App& root);
}  // namespace sogmm::tools
