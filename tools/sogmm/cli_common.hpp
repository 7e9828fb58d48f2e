// Pieces shared by the `sogmm` subcommands: camera flags, evaluation, errors.
#pragma once

#include <cstdint>
#include <functional>
#include <initializer_list>
#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json_fwd.hpp>

#include "image_io.hpp"
#include "sogmm/camera.hpp"
#include "sogmm/fit.hpp"
#include "sogmm/metrics.hpp"

namespace sogmm::tools {

/// Exit codes of every sogmm tool.
/// kExitInterrupted: cancelled by SIGINT (128 + 2, the shell's convention).
enum ExitCode { kExitOk = 0, kExitUsage = 2, kExitInvalidData = 3, kExitIo = 4, kExitInterrupted = 130 };

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

/// Back-projects the valid pixels of a loaded frame; throws Error(InvalidData)
/// naming `depth_path` and the valid depth range when there is none.
PointCloud backproject_nonempty(const LoadedFrame& frame, const Camera& camera, const DepthOptions& depth,
                                const std::string& depth_path);

/// Fit flags: --bandwidth S | --components K, --seed, --n-init, --threads,
/// --tol, --max-iter, --reg-covar auto|VALUE, --truncate.
void add_fit_flags(CLI::App& app, FitOptions& options);

/// --em-acceleration none|squarem into em.acceleration (part of add_fit_flags;
/// on its own for tools with their own fit flags, e.g. sogmm-perf).
void add_em_acceleration_flag(CLI::App& app, EmOptions& em);

/// Where frames come from: one pair (--depth D --color C) or a posed sequence
/// (--sequence DIR --trajectory FILE [--frames RANGE]).
struct FrameSource {
  std::string depth, color;
  std::string sequence, trajectory, frames;
  bool pair_by_order = false;  ///< --pair-by-order (see sequence.hpp, pair_frames)
};
/// Adds the five flags. `sequence_use` is prefixed to the help of the
/// sequence flags (e.g. "with MODEL: "), where a command restricts them.
void add_frame_source_flags(CLI::App& app, FrameSource& source, const std::string& sequence_use = "");
/// Adds --pair-by-order (commands that take --sequence without the other flags).
void add_pair_by_order_flag(CLI::App& app, bool& pair_by_order);

/// Everything `sogmm eval` reports about one fit.
struct Evaluation {
  FitResult fit;
  PsnrResult psnr;
  ReconstructionResult reconstruction;
  std::size_t model_bytes = 0;
};
/// Evaluates a model against the cloud it came from (camera = decimated camera).
Evaluation evaluate(FitResult fit, const PointsView& truth, const Camera& decimated_camera, std::uint64_t seed,
                    double data_range = 1.0);

/// Adds --data-range (into `data_range`): the peak of the honest PSNR (1 for
/// gray in [0, 1], 0 = the frame's actual gray range); the paper-compatible
/// PSNR keeps the authors' range 2 whatever it is (sogmm::psnr_images).
void add_data_range_flag(CLI::App& app, double& data_range);

/// Runs `body`, turning sogmm::Error and other exceptions into a one-line
/// message on stderr ("sogmm: error: ...") and the documented exit code.
int run_guarded(const std::function<int()>& body);

}  // namespace sogmm::tools

namespace sogmm::tools {
/// Prints an evaluation as a human table, or with `json` as one JSON object
/// with keys n_points, n_components, psnr, psnr_paper, psnr_data_range (the
/// honest PSNR's peak; the paper figure always uses 2), mre, precision, recall,
/// fscore, model_bytes, em_iterations, converged, log_likelihood, n_init,
/// run, run_log_likelihoods, seconds_mode_count, seconds_seeding, seconds_em,
/// seconds_total, plus the members of `extra` (if given) in JSON mode.
void print_evaluation(const Evaluation& e, bool json, const nlohmann::json* extra = nullptr);

/// A subcommand: its CLI11 parser and what to run when it is chosen.
struct Command {
  CLI::App* app = nullptr;
  std::function<int()> run;
};
Command add_demo_command(CLI::App& root);
Command add_eval_command(CLI::App& root);
Command add_fit_command(CLI::App& root);
Command add_map_command(CLI::App& root);
Command add_apply_deltas_command(CLI::App& root);
Command add_render_command(CLI::App& root);
Command add_sample_command(CLI::App& root);
Command add_query_command(CLI::App& root);
Command add_view_command(CLI::App& root);

/// True when any of the named options was given on the command line.
bool any_given(const CLI::App& app, std::initializer_list<const char*> names);

/// The camera flags were used (--intrinsics or any of --fx/--fy/--cx/--cy/--width/--height).
bool camera_flags_given(const CameraFlags& flags);
/// Camera from explicit flags only (no frame to take the size from: --width
/// and --height are then required). Throws Error(InvalidArgument).
Camera camera_from_flags(const CameraFlags& flags);

/// Where fit progress goes: nowhere, plain lines, or one live line on a terminal.
enum class ProgressMode { Off, Lines, Live };
/// Off with --quiet; Live when stderr is a terminal; Lines with --progress; else Off.
ProgressMode progress_mode(bool quiet, bool lines);

/// Prints fit stages on stderr (see ProgressMode); `label` prefixes each line.
class ProgressPrinter {
 public:
  explicit ProgressPrinter(ProgressMode mode) : mode_(mode) {}
  ~ProgressPrinter() { finish(); }
  ProgressPrinter(const ProgressPrinter&) = delete;
  ProgressPrinter& operator=(const ProgressPrinter&) = delete;
  /// The sink for sogmm::fit(): prints stages (times measured between
  /// reports) and cancels once SIGINT arrived (see SigintCancel), in every
  /// mode, Off included.
  ProgressSink fit_callback(const std::string& label);
  /// A line that stays (e.g. "frame 2/3 done"): printed in Lines and Live modes.
  void line(const std::string& text);
  /// "EM done in T s: I iterations, mean log-likelihood L" after a fit (Lines mode).
  void em_done(const std::string& label, const FitResult& r);
  /// The same from its parts (a fit run inside the core Map).
  void em_done(const std::string& label, double seconds_em, int iterations, double log_likelihood);
  /// A line the next one replaces on a terminal (Live); printed in Lines mode.
  void status(const std::string& text);
  /// Clears a pending live line.
  void finish();

 private:
  void show(const std::string& text, bool keep);
  ProgressMode mode_;
  bool live_pending_ = false;
};

/// Milliseconds since 1970 UTC, now.
std::int64_t unix_ms_now();
/// Human byte count, e.g. "41.2 KiB (42188 bytes)".
std::string human_bytes(std::uint64_t bytes);
}  // namespace sogmm::tools
