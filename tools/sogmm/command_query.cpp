// `sogmm query`: what a planner asks a model or map at given points: P(occupied)
// and free / occupied / unknown (maps), the distance to the surface and its
// gradient, and the collision probability of a spherical robot there.
#include <algorithm>
#include <cmath>
#include <array>
#include <cstdio>
#include <memory>
#include <optional>

#include "cli_common.hpp"
#include "file_util.hpp"
#include "model_io.hpp"
#include "point_table.hpp"
#include "sogmm/collision.hpp"
#include "sogmm/error.hpp"
#include "sogmm/map.hpp"
#include "sogmm/occupancy.hpp"
#include "sogmm/surface_distance.hpp"

namespace sogmm::tools {

namespace {

struct QueryState {
  std::string model, points, output;
  bool occupancy = false, distance = false, gradient = false;
  double robot_radius = 0;
  int threads = 0;
  OccupancyOptions occupancy_options;
  SurfaceDistanceOptions surface_options;
};

int run_query(const QueryState& s) {
  require(s.occupancy || s.distance || s.gradient || s.robot_radius > 0, ErrorCode::InvalidArgument,
          "query: ask for something: --occupancy, --distance, --gradient and/or --robot-radius R");
  require(s.robot_radius >= 0 && std::isfinite(s.robot_radius), ErrorCode::InvalidArgument,
          "query: --robot-radius must be finite and > 0");
  require(s.threads >= 0, ErrorCode::InvalidArgument, "query: --threads must be >= 0");
  check_outputs({{"MODEL", s.model}, {"--points", s.points}}, {{"-o", s.output}});
  validate(s.occupancy_options);
  validate(s.surface_options);
  const Model model = load_model(s.model);
  const std::vector<float> xyz = read_points(s.points);
  const std::size_t n = xyz.size() / 3;

  std::vector<Column> columns;
  for (int k = 0; k < 3; ++k) {
    Column c{std::string(1, "xyz"[k]), std::vector<double>(n)};
    for (std::size_t i = 0; i < n; ++i) c.values[i] = xyz[3 * i + k];
    columns.push_back(std::move(c));
  }
  std::string summary;
  if (s.occupancy) {
    // Occupancy needs the frames a map records; from_model refuses a model
    // in a camera frame, naming it.
    const Map map = Map::from_model(model);
    std::vector<double> p(n);
    std::vector<std::uint8_t> state(n);
    sogmm::occupancy(map, xyz.data(), n, p.data(), state.data(), s.occupancy_options, s.threads);
    std::array<std::size_t, 3> count{};
    Column st{"state", std::vector<double>(n)};
    for (std::size_t i = 0; i < n; ++i) {
      ++count[state[i]];
      st.values[i] = state[i];
    }
    columns.push_back({"p_occupied", std::move(p)});
    columns.push_back(std::move(st));
    summary += "; " + std::to_string(count[0]) + " free, " + std::to_string(count[1]) + " occupied, " +
               std::to_string(count[2]) + " unknown (" + std::to_string(map.frames().size()) + " frames)";
  }
  if (s.distance || s.gradient) {
    std::vector<double> d(n), g(s.gradient ? 3 * n : 0);
    surface_distance(model.gmm, xyz.data(), n, d.data(), s.gradient ? g.data() : nullptr, s.surface_options,
                     s.threads);
    std::vector<double> sorted = d;
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(n / 2), sorted.end());
    char buf[64];
    std::snprintf(buf, sizeof buf, "; median distance %.4g m", sorted[n / 2]);
    summary += buf;
    columns.push_back({"distance", std::move(d)});
    for (int k = 0; k < 3 && s.gradient; ++k) {
      Column c{std::string("g") + "xyz"[k], std::vector<double>(n)};
      for (std::size_t i = 0; i < n; ++i) c.values[i] = g[3 * i + k];
      columns.push_back(std::move(c));
    }
  }
  if (s.robot_radius > 0) {
    std::vector<double> centers(xyz.begin(), xyz.end()), shapes(9 * n, 0.0), p(n);
    for (std::size_t i = 0; i < n; ++i)
      for (int k = 0; k < 3; ++k) shapes[9 * i + 4 * k] = s.robot_radius * s.robot_radius;  // S = r^2 I
    collision_probability(model.gmm, centers.data(), shapes.data(), n, p.data(), s.surface_options, s.threads);
    const std::size_t risky = static_cast<std::size_t>(std::count_if(p.begin(), p.end(), [](double v) { return v >= 0.5; }));
    summary += "; " + std::to_string(risky) + " robots with P(collision) >= 0.5";
    columns.push_back({"p_collision", std::move(p)});
  }
  write_columns(s.output, columns);
  std::printf("Wrote %s: %zu points, %zu columns%s.\n", s.output.c_str(), n, columns.size(), summary.c_str());
  return 0;
}

}  // namespace

Command add_query_command(CLI::App& root) {
  auto s = std::make_shared<QueryState>();
  CLI::App* app = root.add_subcommand("query", "Ask a model or map at points: occupancy, distance, collision");
  app->footer(
      "Points: .npy (float32/float64, shape (n, >= 3)) or text with x y z per line (commas, spaces or tabs;\n"
      "'#' comments and a header line are skipped), in the model's frame (world for a map).\n"
      "Output: columns x, y, z, then p_occupied and state (0 free, 1 occupied, 2 unknown) for --occupancy,\n"
      "distance (metres to the nearest surface disc) for --distance, gx gy gz (unit vector away from the\n"
      "surface) for --gradient, p_collision of a sphere of --robot-radius at each point; CSV, or a float64\n"
      "(n, columns) .npy when -o ends in .npy. Occupancy needs a map (its frames say what was observed);\n"
      "the model, formula and options are in spec/api.md, section 4.9.\n\n"
      "Examples:\n"
      "  sogmm query room.sogmm --points probes.csv --occupancy --distance -o answers.csv\n"
      "  sogmm query room.sogmm --points path.npy --robot-radius 0.3 -o risk.npy");
  app->add_option("model", s->model, "saved model or map (.sogmm)")->required();
  app->add_option("--points", s->points, "query points (.npy or text)")->required();
  app->add_option("-o,--output", s->output, "output table (.csv or .npy)")->required();
  app->add_flag("--occupancy", s->occupancy, "P(occupied) and free/occupied/unknown (a map)");
  app->add_flag("--distance", s->distance, "distance to the surface");
  app->add_flag("--gradient", s->gradient, "the distance's gradient (adds --distance)");
  app->add_option("--robot-radius", s->robot_radius, "P(collision) of a sphere of this radius (m) at each point");
  app->add_option("--surface-sigma", s->occupancy_options.surface_sigma,
                  "occupancy: the surface's standard deviation along a ray (m)")
      ->capture_default_str();
  app->add_option("--thickness", s->occupancy_options.thickness, "occupancy: half-thickness of the occupied shell (m)")
      ->capture_default_str();
  app->add_option("--disc-sigmas", s->surface_options.disc_sigmas,
                  "distance, collision: component discs out to this many sigmas")
      ->capture_default_str();
  app->add_option("--threads", s->threads, "worker threads (0 = all)")->capture_default_str();
  return {app, [s]() { return run_query(*s); }};
}

}  // namespace sogmm::tools
