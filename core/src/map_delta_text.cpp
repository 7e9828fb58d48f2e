// A map delta as a model with the kDelta* keys (spec/format.md section 2.5):
// the form the file format carries.
#include <cinttypes>
#include <cstdio>
#include <sstream>
#include <string>

#include "sogmm/error.hpp"
#include "sogmm/map_delta.hpp"
#include "text_rows.hpp"

namespace sogmm {
namespace {

const char* op_name(DeltaOp::Kind k) {
  switch (k) {
    case DeltaOp::Kind::Merge: return "merge";
    case DeltaOp::Kind::Remove: return "remove";
    case DeltaOp::Kind::Set: return "set";
    case DeltaOp::Kind::Drop: return "drop";
  }
  return "?";
}

std::string ops_text(const std::vector<DeltaOp>& ops) {
  std::string text;
  for (const DeltaOp& op : ops) {
    text += op_name(op.kind);
    if (op.kind == DeltaOp::Kind::Merge) {
      text += " " + std::to_string(op.count) + " " + std::to_string(op.support);
    } else {
      for (std::uint64_t id : op.ids) text += " " + std::to_string(id);
    }
    text += "\n";
  }
  return text;
}

Error bad_key(const char* key, const std::string& why) {
  return Error(ErrorCode::Format, std::string("map delta: key ") + key + ": " + why);
}

const std::string& value(const Model& m, const char* key) {
  const std::string* v = find_value(m, key);
  if (v == nullptr) throw bad_key(key, "missing (not a map delta)");
  return *v;
}

// A decimal count: digits only (no sign, no space), at most 19 of them.
bool parse_count(const std::string& token, std::uint64_t& out) {
  if (token.empty() || token.size() > 19 || token.find_first_not_of("0123456789") != std::string::npos) return false;
  out = std::stoull(token);
  return true;
}

std::uint64_t count_of(const Model& m, const char* key) {
  std::uint64_t v = 0;
  if (!parse_count(value(m, key), v)) throw bad_key(key, "'" + value(m, key) + "' is not a decimal count");
  return v;
}

std::vector<DeltaOp> parse_ops(const std::string& text) {
  std::vector<DeltaOp> ops;
  detail::for_each_text_row(text, std::string("map delta: key ") + kDeltaOpsKey, [&](std::istream& row, auto bad) {
    std::string name, token;
    row >> name;
    std::vector<std::uint64_t> numbers;
    while (row >> token) {
      std::uint64_t v = 0;
      if (!parse_count(token, v)) throw bad("'" + token + "' is not a decimal count");
      numbers.push_back(v);
    }
    DeltaOp op;
    if (name == "merge") {
      if (numbers.size() != 2) throw bad("expected 'merge count support'");
      op.kind = DeltaOp::Kind::Merge;
      op.count = numbers[0];
      op.support = numbers[1];
    } else if (name == "remove" || name == "set" || name == "drop") {
      if (numbers.empty()) throw bad("'" + name + "' names no component");
      op.kind = name == "remove" ? DeltaOp::Kind::Remove : name == "set" ? DeltaOp::Kind::Set : DeltaOp::Kind::Drop;
      op.ids = std::move(numbers);
    } else {
      throw bad("unknown step '" + name + "'");
    }
    ops.push_back(std::move(op));
  });
  return ops;
}

}  // namespace

Model delta_to_model(const MapDelta& d) {
  Model m = d.model;
  char digest[24];
  std::snprintf(digest, sizeof digest, "%016" PRIx64, d.digest);
  m.key_values.emplace_back(kDeltaMapIdKey, d.map_id);
  m.key_values.emplace_back(kDeltaBaseRevisionKey, std::to_string(d.base_revision));
  m.key_values.emplace_back(kDeltaRevisionKey, std::to_string(d.revision));
  m.key_values.emplace_back(kDeltaFramesBeforeKey, std::to_string(d.frames_before));
  m.key_values.emplace_back(kDeltaFramesFromKey, std::to_string(d.frames_from));
  m.key_values.emplace_back(kDeltaFramesKey, d.frames);
  m.key_values.emplace_back(kDeltaOpsKey, ops_text(d.ops));
  m.key_values.emplace_back(kDeltaDigestKey, digest);
  return m;
}

MapDelta delta_from_model(const Model& m) {
  MapDelta d;
  d.map_id = value(m, kDeltaMapIdKey);
  if (d.map_id.size() != 32 || d.map_id.find_first_not_of("0123456789abcdef") != std::string::npos)
    throw bad_key(kDeltaMapIdKey, "not 32 lowercase hex digits");
  d.base_revision = count_of(m, kDeltaBaseRevisionKey);
  d.revision = count_of(m, kDeltaRevisionKey);
  if (d.revision < d.base_revision) throw bad_key(kDeltaRevisionKey, "below the base revision");
  d.frames_before = count_of(m, kDeltaFramesBeforeKey);
  d.frames_from = count_of(m, kDeltaFramesFromKey);
  if (d.frames_from > d.frames_before) throw bad_key(kDeltaFramesFromKey, "after the frames before the delta");
  d.frames = value(m, kDeltaFramesKey);
  d.ops = parse_ops(value(m, kDeltaOpsKey));
  std::uint64_t explicit_count = 0;
  for (const DeltaOp& op : d.ops)
    explicit_count += op.kind == DeltaOp::Kind::Merge ? op.count : op.kind == DeltaOp::Kind::Set ? op.ids.size() : 0;
  if (explicit_count != m.gmm.size())
    throw bad_key(kDeltaOpsKey, "the steps use " + std::to_string(explicit_count) + " explicit components, the delta carries " +
                                    std::to_string(m.gmm.size()));
  const std::string& digest = value(m, kDeltaDigestKey);
  if (digest.size() != 16 || digest.find_first_not_of("0123456789abcdef") != std::string::npos)
    throw bad_key(kDeltaDigestKey, "not 16 lowercase hex digits");
  d.digest = std::stoull(digest, nullptr, 16);
  d.model = m;
  for (const char* key : {kDeltaMapIdKey, kDeltaBaseRevisionKey, kDeltaRevisionKey, kDeltaFramesBeforeKey,
                          kDeltaFramesFromKey, kDeltaFramesKey, kDeltaOpsKey, kDeltaDigestKey})
    erase_value(d.model, key);
  return d;
}

}  // namespace sogmm
