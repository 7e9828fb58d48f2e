// `sogmm`: the command-line face of the library.
#include <cstdio>
#include <vector>

#include "bench/bench.hpp"
#include "cli_common.hpp"
#include "sogmm/model.hpp"

int main(int argc, char** argv) {
  using namespace sogmm::tools;
  CLI::App app{"sogmm: self-organizing Gaussian mixture models of RGB-D frames"};
  app.set_version_flag("--version", std::string("sogmm ") + sogmm::version_string());
  app.require_subcommand(1);
  app.footer(
      "Exit codes: 0 ok, 2 usage error, 3 invalid input data, 4 I/O error (one line on stderr names the\n"
      "file and the problem). Run sogmm SUBCOMMAND --help for the flags and an example.\n\n"
      "Example (a frame of ../shared/data/rgbd/livingroom):\n"
      "  D=../shared/data/rgbd/livingroom\n"
      "  sogmm fit --depth $D/depth/00000.png --color $D/color/00000.jpg --intrinsics $D/intrinsics.json \\\n"
      "    --decimate 5 --bandwidth 0.02 -o frame0.sogmm\n"
      "  sogmm eval frame0.sogmm --depth $D/depth/00000.png --color $D/color/00000.jpg\n"
      "  sogmm render frame0.sogmm --compare --depth $D/depth/00000.png --color $D/color/00000.jpg -o cmp.png\n"
      "  sogmm sample frame0.sogmm -n 100000 -o samples.ply --ellipsoids ellipsoids.ply\n"
      "  sogmm query room.sogmm --points probes.csv --occupancy --distance -o answers.csv");
  std::vector<Command> commands = {add_demo_command(app),   add_eval_command(app),  add_fit_command(app),
                                   add_map_command(app),    add_apply_deltas_command(app),    add_render_command(app), add_sample_command(app),
                                   add_query_command(app),  add_view_command(app),  add_bench_command(app)};
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version exit 0; real usage errors get one line and code 2.
    if (e.get_exit_code() == 0) return app.exit(e);
    std::fprintf(stderr, "sogmm: usage error: %s (see sogmm --help)\n", e.what());
    return kExitUsage;
  }
  for (const Command& c : commands)
    if (c.app->parsed()) return run_guarded(c.run);
  return kExitUsage;
}
