// The methods `sogmm bench` compares and how each is scored.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "sogmm/camera.hpp"
#include "sogmm/em.hpp"
#include "sogmm/model.hpp"
#include "sogmm/point_cloud.hpp"

namespace sogmm::bench {

/// What to run. Families: "octomap", "ndt", "fc", "sogmm".
struct BenchConfig {
  std::vector<double> octomap_resolutions{0.02, 0.05};
  bool octomap_ray_cast = true;  ///< false: endpoints only, no free space in the tree
  std::vector<double> ndt_resolutions{0.02, 0.05};
  std::vector<std::size_t> fc_components{75, 500, 2000};
  std::vector<double> bandwidths{0.01, 0.02, 0.03};
  std::vector<std::string> families{"octomap", "ndt", "fc", "sogmm"};
  std::uint64_t seed = 0;  ///< fit seed and sampling seed, as `sogmm eval --seed`
  EmOptions em;            ///< EM options of the FC and SOGMM fits
  double threshold = 0.01; ///< precision/recall distance (m)
  CameraInfo camera_info;  ///< stored in the .sogmm bytes whose size is reported
};

/// One method on one frame. Sizes are bytes; -1 = not applicable.
struct BenchRow {
  std::string frame;
  std::string method;        ///< "OM-0.02", "NDT-0.05", "FC-75", "SOGMM-0.01"
  std::string family;        ///< octomap | ndt | fc | sogmm
  double parameter = 0.0;    ///< resolution (m), K, or bandwidth
  std::size_t n_points = 0;  ///< ground-truth points N
  std::size_t n_elements = 0;  ///< occupied leaves / voxels / components M
  double psnr = 0.0;
  double psnr_paper = 0.0;
  double mre = 0.0;
  double precision = 0.0;    ///< authors' naming (see sogmm/metrics.hpp)
  double recall = 0.0;
  double fscore = 0.0;
  long long memory_bytes = -1;  ///< paper's count (.ot size for OctoMap)
  long long file_bytes = -1;    ///< real file: .sogmm for GMMs, .ot for OctoMap
  double build_seconds = 0.0;   ///< model construction time
  std::size_t gray_fallbacks = 0;  ///< queries answered by the nearest occupied cell
  std::string note;
};

/// Validates family names; throws Error(InvalidArgument) naming a bad one.
void validate(const BenchConfig& config);

/// Runs every configured method on one frame. `truth` is the back-projected
/// cloud (camera frame), `camera` the decimated camera used for PSNR.
/// `log` (may be empty) receives one progress line per method and notes such
/// as "OctoMap not built: skipped".
std::vector<BenchRow> run_frame(const std::string& frame, const PointsView& truth, const Camera& camera,
                                const BenchConfig& config, const std::function<void(const std::string&)>& log = {});

/// Markdown table of the rows (one row per frame and method).
std::string markdown_table(const std::vector<BenchRow>& rows);
/// CSV with a header line; throws Error(Io).
void write_csv(const std::string& path, const std::vector<BenchRow>& rows);

}  // namespace sogmm::bench
