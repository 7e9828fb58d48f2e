// `sogmm apply-deltas DIR -o MAP [--base MAP0]`: rebuild a map from the
// deltas `sogmm map --deltas DIR` wrote (spec/format.md 2.5), in name order,
// from an empty map or a base map; a gap, a duplicate or a damaged delta
// stops it with the file's name, and nothing is written.
#include <cstdio>
#include <memory>

#include <nlohmann/json.hpp>

#include "cli_common.hpp"
#include "file_util.hpp"
#include "map_deltas.hpp"
#include "model_io.hpp"
#include "sogmm/error.hpp"
#include "sogmm/map_delta.hpp"
#include "sogmm/map_delta_file.hpp"

namespace sogmm::tools {
namespace {

struct ApplyState {
  std::string dir, output, base;
  bool json = false;
};

int run_apply(const ApplyState& s) {
  std::vector<NamedFile> inputs;
  if (!s.base.empty()) inputs.push_back({"--base", s.base});
  check_outputs(inputs, {{"-o", s.output}});
  Map map = s.base.empty() ? Map() : Map::from_model(load_model(s.base));
  const std::uint64_t first = map.revision();
  std::size_t applied = 0;
  for (const std::string& file : delta_files(s.dir)) {
    try {
      const MapDelta delta = format::load_delta(file);
      // Deltas the base already holds (it was saved after them) are skipped.
      if (delta.map_id == map.id() && delta.revision <= map.revision() && applied == 0) continue;
      map.apply_delta(delta);
      ++applied;
    } catch (const Error& e) {
      // A delta that does not follow (a gap, a duplicate, another map's) is
      // bad input data here, not a bad command line.
      throw Error(e.code() == ErrorCode::InvalidArgument ? ErrorCode::InvalidData : e.code(), file + ": " + e.what());
    }
  }
  require(applied > 0, ErrorCode::InvalidArgument,
          s.dir + ": no delta after revision " + std::to_string(first) + " of the base map");
  const std::uint64_t bytes = save_model(s.output, map.to_model());
  if (s.json) {
    nlohmann::json j;
    j["output"] = s.output;
    j["n_deltas"] = applied;
    j["revision"] = map.revision();
    j["n_components"] = map.size();
    j["n_frames"] = map.frames().size();
    j["file_bytes"] = bytes;
    std::printf("%s\n", j.dump().c_str());
  } else {
    std::printf("Applied %zu deltas (revision %llu to %llu): %zu components, %zu frames. Wrote %s (%s).\n", applied,
                static_cast<unsigned long long>(first), static_cast<unsigned long long>(map.revision()), map.size(),
                map.frames().size(), s.output.c_str(), human_bytes(bytes).c_str());
  }
  return 0;
}

}  // namespace

Command add_apply_deltas_command(CLI::App& root) {
  auto s = std::make_shared<ApplyState>();
  CLI::App* app = root.add_subcommand("apply-deltas", "Rebuild a map from the deltas of sogmm map --deltas");
  app->footer(
      "Applies DIR/delta-*.sogmm in name order (the order sogmm map wrote them) to an empty map, or to\n"
      "--base (a map file saved by the sender: deltas it already holds are skipped). The result is the\n"
      "sender's map bit for bit. A missing delta (a gap), a duplicate, another map's or a damaged delta\n"
      "stops it with an error naming the file; -o is then not written.\n\n"
      "Example:\n"
      "  sogmm map /tmp/loop --trajectory /tmp/loop/trajectory.log -o loop.sogmm --deltas /tmp/loop-deltas\n"
      "  sogmm apply-deltas /tmp/loop-deltas -o rebuilt.sogmm");
  app->add_option("DIR", s->dir, "folder of delta-*.sogmm files")->required();
  app->add_option("-o,--output", s->output, "the rebuilt map (.sogmm)")->required();
  app->add_option("--base", s->base, "start from this map file instead of an empty map");
  app->add_flag("--json", s->json, "print the summary as one JSON object");
  return {app, [s]() { return run_apply(*s); }};
}

}  // namespace sogmm::tools
