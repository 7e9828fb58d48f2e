// `sogmm view`: one self-contained HTML page that shows a model in a browser
// (the JavaScript reader of bindings/js and three.js, embedded with the
// model's bytes), opened from disk, offline.
#include <cstdio>
#include <fstream>
#include <iterator>
#include <memory>

#include "cli_common.hpp"
#include "file_util.hpp"
#include "sogmm/error.hpp"
#include "sogmm/format.hpp"
#include "serve_page.hpp"
#include "viewer_page.hpp"

namespace sogmm::tools {
namespace {

// The reader's cap on decoded arrays (spec section 8) plus room for metadata:
// a file beyond it is refused by every default reader, the page's included.
constexpr std::uint64_t kMaxViewBytes = (std::uint64_t{1} << 30) + (std::uint64_t{1} << 28);

std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  require(static_cast<bool>(in), ErrorCode::Io, path + ": cannot open for reading");
  const std::uint64_t size = file_size_or_zero(path);
  require(size <= kMaxViewBytes, ErrorCode::Limit, path + ": larger than 1.25 GiB, too large to view");
  std::string bytes(std::istreambuf_iterator<char>(in), {});
  require(!in.bad(), ErrorCode::Io, path + ": read error");
  return bytes;
}

std::string base_name(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

std::string default_output(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  const std::size_t dot = path.find_last_of('.');
  const bool has_ext = dot != std::string::npos && (slash == std::string::npos || dot > slash);
  return (has_ext ? path.substr(0, dot) : path) + ".html";
}

}  // namespace

Command add_view_command(CLI::App& root) {
  struct State {
    std::string model, output;
    bool embed_invalid = false;
    bool serve = false;
    int port = 0;
  };
  auto s = std::make_shared<State>();
  CLI::App* app = root.add_subcommand("view", "Write a self-contained HTML page that shows a model in a browser");
  app->footer(
      "The page embeds the model and the viewer (an independent JavaScript reader of the format and\n"
      "three.js); it needs no network and no server: open it from disk. It draws the components as\n"
      "ellipsoids (1, 2 or 3 sigma, coloured by mean gray or weight), optional sampled points, a map's\n"
      "cameras with a slider over its frames (the map after each frame), a clicked component's weight,\n"
      "mean, covariance and eigenvalues, and the file's metadata. Drop any .sogmm on the page to open it.\n"
      "A file the reader rejects is refused (exit 3) unless --embed-invalid, whose page shows the reason.\n\n"
      "Examples:\n"
      "  sogmm view frame0.sogmm                # writes frame0.html\n"
      "  sogmm view map.sogmm -o map.html\n"
      "  sogmm view map.sogmm --serve          # http://127.0.0.1:PORT/ until Ctrl-C");
  app->add_option("model", s->model, "model to show (.sogmm)")->required();
  app->add_option("-o,--output", s->output, "output page (.html; default: the model's name with .html)");
  app->add_flag("--embed-invalid", s->embed_invalid,
                "write the page even when the file is rejected (the page shows the reader's reason)");
  app->add_flag("--serve", s->serve,
                "serve the page on http://127.0.0.1:PORT/ (printed) until Ctrl-C instead of writing it "
                "(it is written too when -o is given)");
  app->add_option("--port", s->port, "port for --serve (default 0: a free one)")
      ->check(CLI::Range(0, 65535))
      ->needs(app->get_option("--serve"));
  return {app, [s]() {
            const bool write = !s->serve || !s->output.empty();
            const std::string out = s->output.empty() ? default_output(s->model) : s->output;
            if (write) check_output_path(out);
            const std::string bytes = read_bytes(s->model);
            if (!s->embed_invalid) {
              try {
                (void)format::from_bytes(bytes.data(), bytes.size());
              } catch (const Error& e) {
                throw Error(e.code(), s->model + ": " + e.what() + " (--embed-invalid writes the page anyway)");
              }
            }
            const std::string page = viewer_page(bytes, base_name(s->model));
            if (write) {
              write_file_atomic(out, page.data(), page.size());
              std::printf("wrote %s (%zu bytes)\n", out.c_str(), page.size());
            }
            if (s->serve) serve_page(page, s->port);
            return static_cast<int>(kExitOk);
          }};
}

}  // namespace sogmm::tools
