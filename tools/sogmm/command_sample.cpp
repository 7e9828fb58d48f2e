// `sogmm sample`: draw points from a model into a PLY point cloud, and/or
// write the components' ellipsoids as a PLY triangle mesh.
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>

#include "cli_common.hpp"
#include "file_util.hpp"
#include "model_io.hpp"
#include "ply.hpp"
#include "sogmm/error.hpp"
#include "sogmm/inference.hpp"

namespace sogmm::tools {

Command add_sample_command(CLI::App& root) {
  struct State {
    std::string model, output, ellipsoids;
    long long n = -1;
    std::uint64_t seed = 0;
    double truncation = sogmm::kDefaultSampleTruncation, sigmas = 2.0;
    int subdivisions = 1;
  };
  auto s = std::make_shared<State>();
  CLI::App* app = root.add_subcommand("sample", "Sample a model into a PLY point cloud; export component ellipsoids");
  app->footer(
      "Points: binary little-endian PLY, float x y z (metres, the model's frame), float intensity (sampled\n"
      "gray), uchar red green blue (gray clamped to 0..255); opens in MeshLab, CloudCompare and Open3D.\n"
      "Ellipsoids: one icosphere mesh per component mapped onto the 2-sigma ellipsoid of its spatial\n"
      "(x, y, z) covariance, colored by the mean gray. Files are written atomically.\n\n"
      "Examples:\n"
      "  sogmm sample frame0.sogmm -n 200000 --seed 1 -o samples.ply\n"
      "  sogmm sample frame0.sogmm --ellipsoids ellipsoids.ply");
  app->add_option("model", s->model, "saved model (.sogmm)")->required();
  app->add_option("-o,--output", s->output, "output point cloud (.ply)");
  app->add_option("-n,--count", s->n, "number of samples (default: the model's support size)");
  app->add_option("--seed", s->seed, "random seed")->capture_default_str();
  app->add_option("--truncation", s->truncation, "truncate each standard-normal coordinate to (-t, t) (0 = none)")
      ->capture_default_str();
  app->add_option("--ellipsoids", s->ellipsoids, "also write the components' ellipsoids as a mesh (.ply)");
  app->add_option("--sigmas", s->sigmas, "ellipsoid radius in standard deviations")->capture_default_str();
  app->add_option("--subdivisions", s->subdivisions, "icosphere subdivisions (0: 12 vertices, 1: 42, 2: 162)")
      ->capture_default_str();
  return {app, [s]() {
            require(!s->output.empty() || !s->ellipsoids.empty(), ErrorCode::InvalidArgument,
                    "sample: give -o OUT.ply and/or --ellipsoids OUT.ply");
            require(s->n != 0 && s->n >= -1 && s->n <= 100000000, ErrorCode::InvalidArgument,
                    "sample: -n must be in 1..100000000");
            require(s->truncation >= 0 && s->sigmas > 0, ErrorCode::InvalidArgument,
                    "sample: --truncation must be >= 0 and --sigmas > 0");
            require(s->subdivisions >= 0 && s->subdivisions <= 4, ErrorCode::InvalidArgument,
                    "sample: --subdivisions must be in 0..4");
            check_outputs({{"MODEL", s->model}}, {{"-o", s->output}, {"--ellipsoids", s->ellipsoids}});
            const Model model = load_model(s->model);
            if (!s->output.empty()) {
              std::size_t n = s->n > 0 ? static_cast<std::size_t>(s->n)
                                       : static_cast<std::size_t>(model.gmm.support_size);
              require(n > 0 && n <= 100000000, ErrorCode::InvalidArgument,
                      "sample: " + s->model + " has support size " + std::to_string(model.gmm.support_size) +
                          "; give -n N (1..100000000)");
              std::vector<float> pts(4 * n);
              const double trunc = s->truncation > 0 ? s->truncation : std::numeric_limits<double>::infinity();
              sample(model.gmm, n, s->seed, 4, pts.data(), trunc);
              write_ply_points(s->output, pts.data(), n,
                               "sogmm sample of " + s->model + ", seed " + std::to_string(s->seed));
              std::printf("Wrote %s: %zu points sampled from %zu components (seed %llu), %s.\n", s->output.c_str(), n,
                          model.gmm.size(), static_cast<unsigned long long>(s->seed),
                          human_bytes(file_size_or_zero(s->output)).c_str());
            }
            if (!s->ellipsoids.empty()) {
              const std::size_t nv = write_ply_ellipsoids(s->ellipsoids, model.gmm, s->sigmas, s->subdivisions,
                                                          "sogmm ellipsoids of " + s->model);
              std::printf("Wrote %s: %zu ellipsoids (%g sigma), %zu vertices, %s.\n", s->ellipsoids.c_str(),
                          model.gmm.size(), s->sigmas, nv, human_bytes(file_size_or_zero(s->ellipsoids)).c_str());
            }
            return 0;
          }};
}

}  // namespace sogmm::tools
