// Lookup, defaults and checked setting over the option registry's rows
// (core/src/option_table.cpp).
#include "sogmm/options.hpp"

#include <cmath>
#include <stdexcept>

#include "sogmm/checked.hpp"
#include "sogmm/error.hpp"

namespace sogmm {
namespace {

const Settings& defaults() {
  static const Settings s{};
  return s;
}

[[noreturn]] void refuse(const OptionSpec& spec, const std::string& value, const std::string& name) {
  throw Error(ErrorCode::InvalidArgument, name + ": value " + value + " out of range (" + spec.range + ")");
}

std::string label(const OptionSpec& spec) {
  return "option key " + std::to_string(static_cast<int>(spec.key)) + " (" + spec.name + ")";
}

bool accepted(const OptionSpec& spec, double v) {
  return !std::isnan(v) && v >= spec.lower && v <= spec.upper && (!spec.accepts_f64 || spec.accepts_f64(v));
}

bool accepted(const OptionSpec& spec, std::int64_t v) {
  return v >= spec.lower_i64 && v <= spec.upper_i64 && (!spec.accepts_i64 || spec.accepts_i64(v));
}

const OptionSpec& row(OptionKey key) {
  const OptionSpec* spec = find_option(static_cast<int>(key));
  if (!spec) throw std::logic_error("option registry: no row for key " + std::to_string(static_cast<int>(key)));
  return *spec;
}

}  // namespace

const OptionSpec* find_option(int key) {
  for (const OptionSpec& spec : option_specs()) {
    if (static_cast<int>(spec.key) == key) return &spec;
  }
  return nullptr;
}

double default_f64(const OptionSpec& spec) { return spec.get_f64(defaults()); }
std::int64_t default_i64(const OptionSpec& spec) { return spec.get_i64(defaults()); }

void set_option(Settings& settings, const OptionSpec& spec, double value) {
  if (!accepted(spec, value)) refuse(spec, checked::exact(value), label(spec));
  spec.set_f64(settings, value);
}

void set_option(Settings& settings, const OptionSpec& spec, std::int64_t value) {
  if (!accepted(spec, value)) refuse(spec, std::to_string(value), label(spec));
  spec.set_i64(settings, value);
}

void require_option(OptionKey key, double value, const std::string& name) {
  const OptionSpec& spec = row(key);
  if (!accepted(spec, value)) refuse(spec, checked::exact(value), name);
}

void require_option(OptionKey key, std::int64_t value, const std::string& name) {
  const OptionSpec& spec = row(key);
  if (!accepted(spec, value)) refuse(spec, std::to_string(value), name);
}

MapOptions map_options(const Settings& s) {
  MapOptions m = s.map;
  m.fit = s.fit;
  m.depth = s.depth;
  validate(m);
  return m;
}

}  // namespace sogmm
