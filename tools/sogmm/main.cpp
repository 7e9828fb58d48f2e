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
  std::vector<Command> commands = {add_demo_command(app), add_eval_command(app), add_bench_command(app)};
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
