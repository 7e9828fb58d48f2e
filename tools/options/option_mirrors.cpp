// Prints the blocks that mirror the option registry (sogmm/options.hpp) in
// the files that cannot read it at run time: the SOGMM_OPT_* macros of
// sogmm.h with their documentation, spec/api.md's option tables, and the key
// constants of the Rust, Python and Go bindings. Every block is a function of
// the registry's rows alone, so a new option is a field and a row, then
// `tools/options/regenerate.py`; ctest options_registry fails while a
// checked-in block differs from what this prints.
//
// Usage: sogmm-option-mirrors header|spec|rust|python|go
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "sogmm/options.hpp"

namespace {

using sogmm::OptionSpec;
using sogmm::OptionType;

// The keys are grouped by hundreds (options.hpp). A group's heading says what
// the keys configure and which calls read them; a key in a new hundred needs
// a heading here, and the generator refuses to print without one.
struct Group {
  const char* title;
  const char* read_by;
};
const std::map<int, Group>& groups() {
  static const std::map<int, Group> g = {
      {1, {"Fit (mode count + k-means++ + EM)",
           "sogmm_fit_points_f32, sogmm_fit_frame and each batch of a map"}},
      {2, {"RGB-D back-projection", "sogmm_fit_frame, sogmm_map_insert_frame, sogmm_frame_to_points_f32"}},
      {3, {"Writing .sogmm", "sogmm_model_save, sogmm_model_save_to_memory, sogmm_map_save"}},
      {4, {"Reading .sogmm",
           "sogmm_model_load, sogmm_model_load_from_memory, sogmm_map_load; MAX_DECODED_BYTES also the saves"}},
      {5, {"Sampling and queries",
           "sogmm_model_sample_f32 (SAMPLE_TRUNCATION); the model's score and regression and the map queries "
           "(QUERY_TRUNCATION_NATS, and THREADS for the team)"}},
      {6, {"Incremental map",
           "sogmm_map_create, sogmm_map_load; a map also reads the fit keys (each batch's fit; THREADS also runs "
           "the novelty test) and the RGB-D keys (sogmm_map_insert_frame)"}},
      {7, {"Occupancy and distance to the surface",
           "sogmm_map_occupancy_f32, sogmm_model_surface_distance_f32, sogmm_map_surface_distance_f32"}},
      {8, {"Registration", "sogmm_register_points_f32 and sogmm_register_model"}},
  };
  return g;
}

const Group& group_of(const OptionSpec& s) {
  const int hundred = static_cast<int>(s.key) / 100;
  auto it = groups().find(hundred);
  if (it == groups().end()) {
    std::cerr << "sogmm-option-mirrors: " << s.name << " is in key group " << hundred * 100
              << ", which has no heading in tools/options/option_mirrors.cpp\n";
    std::exit(1);
  }
  return it->second;
}

int key_of(const OptionSpec& s) { return static_cast<int>(s.key); }

// The shortest decimal that reads back as the same double ("0.02", "1e-06"),
// whole numbers without an exponent ("1000").
std::string shortest(double v) {
  char buf[64];
  if (v == std::floor(v) && std::fabs(v) < 1e15) {
    std::snprintf(buf, sizeof buf, "%.0f", v);
    return buf;
  }
  for (int digits = 1; digits <= 17; ++digits) {
    std::snprintf(buf, sizeof buf, "%.*g", digits, v);
    if (std::strtod(buf, nullptr) == v) break;
  }
  return buf;
}

std::string default_text(const OptionSpec& s) {
  return s.type == OptionType::I64 ? std::to_string(sogmm::default_i64(s)) : shortest(sogmm::default_f64(s));
}

const char* type_text(const OptionSpec& s) { return s.type == OptionType::F64 ? "f64" : "i64"; }

// "f64 (m), > 0, finite; default 0.1."
std::string contract(const OptionSpec& s) {
  std::string out = type_text(s);
  if (*s.unit) out += std::string(" (") + s.unit + ")";
  return out + ", " + s.range + "; default " + default_text(s) + ".";
}

// The doc as a sentence: capitalised, with a full stop.
std::string sentence(const char* doc) {
  std::string out = doc;
  if (!out.empty()) out[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(out[0])));
  return out + ".";
}

// Greedy word wrap: the first line starts with `first`, the others with `rest`.
std::vector<std::string> wrap(const std::string& text, const std::string& first, const std::string& rest,
                              std::size_t width) {
  std::vector<std::string> lines;
  std::string line = first;
  bool empty = true;
  std::istringstream words(text);
  for (std::string w; words >> w;) {
    if (!empty && line.size() + 1 + w.size() > width) {
      lines.push_back(line);
      line = rest;
      empty = true;
    }
    line += (empty ? "" : " ") + w;
    empty = false;
  }
  lines.push_back(line);
  return lines;
}

void check_c_comment(const OptionSpec& s) {
  const std::string text = std::string(s.doc) + s.range + s.unit;
  if (text.find("*/") != std::string::npos || text.find("/*") != std::string::npos) {
    std::cerr << "sogmm-option-mirrors: the row of " << s.name << " contains a C comment delimiter\n";
    std::exit(1);
  }
}

// A block comment within 100 columns, each paragraph on lines of its own.
void print_c_comment(const std::vector<std::string>& paragraphs) {
  std::vector<std::string> lines;
  for (const std::string& p : paragraphs) {
    for (const std::string& l : wrap(p, lines.empty() ? "/* " : " * ", " * ", 97)) lines.push_back(l);
  }
  lines.back() += " */";
  for (const auto& l : lines) std::cout << l << "\n";
}

void print_header() {
  int last_group = -1;
  for (const OptionSpec& s : sogmm::option_specs()) {
    check_c_comment(s);
    const Group& g = group_of(s);
    if (key_of(s) / 100 != last_group) {
      if (last_group != -1) std::cout << "\n";
      last_group = key_of(s) / 100;
      print_c_comment({std::string(g.title) + ". Read by " + g.read_by + "."});
    }
    print_c_comment({sentence(s.doc), contract(s)});
    std::cout << "#define " << s.name << " " << key_of(s) << "\n";
  }
}

// Markdown cell text: a '|' would end the cell.
std::string cell(const std::string& text) {
  std::string out;
  for (char c : text) out += c == '|' ? std::string("\\|") : std::string(1, c);
  return out;
}

void print_spec() {
  int last_group = -1;
  for (const OptionSpec& s : sogmm::option_specs()) {
    const Group& g = group_of(s);
    if (key_of(s) / 100 != last_group) {
      if (last_group != -1) std::cout << "\n";
      last_group = key_of(s) / 100;
      std::cout << "**" << g.title << "**, read by " << g.read_by << ":\n\n"
                << "| Key | Value | Type | Unit | Range | Default | Meaning |\n"
                << "|---|---|---|---|---|---|---|\n";
    }
    std::cout << "| `" << s.name << "` | " << key_of(s) << " | " << type_text(s) << " | " << cell(s.unit) << " | "
              << cell(s.range) << " | " << default_text(s) << " | " << cell(sentence(s.doc)) << " |\n";
  }
}

// "SOGMM_OPT_MAX_DECODED_BYTES" -> "MaxDecodedBytes".
std::string camel(const std::string& name) {
  std::string out;
  bool upper = true;
  for (char c : name.substr(std::string("SOGMM_OPT_").size())) {
    if (c == '_') {
      upper = true;
      continue;
    }
    out += upper ? c : static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    upper = false;
  }
  return out;
}

void print_rust() {
  for (const OptionSpec& s : sogmm::option_specs())
    std::cout << "pub const " << s.name << ": sogmm_key = " << key_of(s) << ";\n";
}

void print_python() {
  for (const OptionSpec& s : sogmm::option_specs())
    std::cout << std::string(s.name).substr(std::string("SOGMM_").size()) << " = " << key_of(s) << "\n";
}

// gofmt's layout: one tab of indent, the names padded to the longest.
void print_go() {
  std::size_t width = 0;
  for (const OptionSpec& s : sogmm::option_specs()) width = std::max(width, camel(s.name).size() + 3);
  // Blank lines keep the marker comments out of the block's doc comment.
  std::cout << "\n// Option keys: the C macros by their Go names (types, ranges, defaults and\n"
               "// meaning: sogmm.h, spec/api.md, or OptionInfoOf at run time).\n"
               "const (\n";
  for (const OptionSpec& s : sogmm::option_specs()) {
    const std::string name = "Opt" + camel(s.name);
    std::cout << "\t" << name << std::string(width - name.size() + 1, ' ') << "Key = C." << s.name << "\n";
  }
  std::cout << ")\n\n";
}

}  // namespace

int main(int argc, char** argv) {
  const std::map<std::string, void (*)()> blocks = {
      {"header", print_header}, {"spec", print_spec}, {"rust", print_rust}, {"python", print_python}, {"go", print_go}};
  auto it = argc == 2 ? blocks.find(argv[1]) : blocks.end();
  if (it == blocks.end()) {
    std::cerr << "usage: sogmm-option-mirrors header|spec|rust|python|go\n";
    return 2;
  }
  it->second();
  return 0;
}
