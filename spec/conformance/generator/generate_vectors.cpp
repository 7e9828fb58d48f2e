// Generates the .sogmm conformance vectors of spec/conformance/ (format 1.0).
//
// RUN ONCE, THEN FROZEN: the vectors and manifest.json in spec/conformance/
// are released artefacts. Never regenerate them over the committed files;
// new vectors get new names (and are appended to the manifest).
//
// Usage: sogmm_conformance_generate OUT_DIR DEPTH.u16 GRAY.f32 WIDTH HEIGHT
// (the raw frame comes from frame_to_raw.py; it is fitted with sogmm::fit).
// Writes OUT_DIR/{valid,invalid}/*.sogmm, OUT_DIR/valid/*.json (canonical
// dumps) and OUT_DIR/manifest.json.
#include <sys/stat.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "frame_record.hpp"
#include "internal.hpp"
#include "sogmm_generated.h"
#include "schema.hpp"
#include "sogmm/camera.hpp"
#include "sogmm/fit.hpp"
#include "sogmm/format.hpp"

namespace {

using namespace sogmm;
namespace fmt = sogmm::format;
namespace det = sogmm::format::detail;

std::string g_out;
std::vector<std::string> g_entries;

std::string quote(const std::string& s) {
  std::string o = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') o += '\\';
    o += c;
  }
  return o + "\"";
}

void write_file(const std::string& rel, const std::vector<std::uint8_t>& bytes) {
  std::ofstream f(g_out + "/" + rel, std::ios::binary);
  f.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  if (!f) throw std::runtime_error("cannot write " + rel);
}

void valid(const std::string& name, const std::vector<std::uint8_t>& bytes, const std::string& description) {
  const std::string rel = "valid/" + name + ".sogmm";
  write_file(rel, bytes);
  const Model m = fmt::from_bytes(bytes.data(), bytes.size());  // must be valid for our reader too
  const fmt::FileInfo info = fmt::read_info(bytes.data(), bytes.size());
  // Stored compact (same values as the canonical dump, no indentation).
  const std::string json = nlohmann::ordered_json::parse(fmt::to_canonical_json(m, &info)).dump() + "\n";
  write_file("valid/" + name + ".json", std::vector<std::uint8_t>(json.begin(), json.end()));
  g_entries.push_back("    {\"file\": " + quote(rel) + ", \"expect\": \"valid\", \"json\": " +
                      quote("valid/" + name + ".json") + ",\n     \"description\": " + quote(description) + "}");
}

void invalid(const std::string& name, const std::vector<std::uint8_t>& bytes, const std::string& category,
             const std::string& reason, const std::string& description) {
  const std::string rel = "invalid/" + name + ".sogmm";
  write_file(rel, bytes);
  // Our own reader must agree before the vector is written into the manifest.
  try {
    fmt::from_bytes(bytes.data(), bytes.size());
    throw std::runtime_error(name + ": accepted by the reference reader");
  } catch (const fmt::FormatError& e) {
    if (e.reason() != reason) throw std::runtime_error(name + ": reference reader says " + e.what());
  }
  g_entries.push_back("    {\"file\": " + quote(rel) + ", \"expect\": \"invalid\", \"category\": " + quote(category) +
                      ", \"reason\": " + quote(reason) + ",\n     \"description\": " + quote(description) + "}");
}

// A small synthetic model with SPD covariances rounded symmetrically to float.
Model synthetic(std::size_t m, std::uint32_t seed) {
  std::uint64_t s = seed * 0x9E3779B97F4A7C15ull + 1;
  auto u = [&]() {
    s ^= s << 13, s ^= s >> 7, s ^= s << 17;
    return static_cast<double>(s >> 11) / 9007199254740992.0;
  };
  Model model;
  Gmm& g = model.gmm;
  g.resize(m);
  std::vector<double> w(m);
  double sum = 0;
  for (auto& x : w) sum += (x = 0.1 + u());
  for (std::size_t k = 0; k < m; ++k) {
    g.weights[k] = static_cast<float>(w[k] / sum);
    const double mean[4] = {2 * u() - 1, 1.5 * u() - 0.75, 0.5 + 2 * u(), u()};
    for (int i = 0; i < 4; ++i) g.means[4 * k + i] = static_cast<float>(mean[i]);
    double a[4][4];
    for (auto& r : a)
      for (double& x : r) x = 0.05 * (u() - 0.5);
    for (int i = 0; i < 4; ++i)
      for (int j = i; j < 4; ++j) {
        double c = i == j ? 1e-5 : 0.0;
        for (int t = 0; t < 4; ++t) c += a[i][t] * a[j][t];
        g.covariances[16 * k + 4 * i + j] = g.covariances[16 * k + 4 * j + i] = static_cast<float>(c);
      }
  }
  g.support_size = 100 * m;
  model.producer_name = "sogmm-conformance";
  model.producer_version = "1.0.0";
  return model;
}

std::vector<std::uint8_t> read_raw(const std::string& path, std::size_t bytes) {
  std::ifstream f(path, std::ios::binary);
  std::vector<std::uint8_t> out(bytes);
  f.read(reinterpret_cast<char*>(out.data()), static_cast<std::streamsize>(bytes));
  if (!f) throw std::runtime_error("cannot read " + path);
  return out;
}

std::vector<std::uint8_t> cut(std::vector<std::uint8_t> b, std::size_t n) {
  b.resize(n);
  return b;
}

fmt::WriteOptions raw_options() {
  fmt::WriteOptions o;
  o.compress = false;
  return o;
}

std::vector<std::uint8_t> uncompressed(const Model& m) { return fmt::to_bytes(m, raw_options()); }

// A file as formats 1.3 and 1.4 wrote it, with the axis lists (their vectors
// came out of this generator before format 1.5 let such files omit them).
std::vector<std::uint8_t> with_axis_lists(const Model& m, const fmt::WriteOptions& o = {}) {
  det::Tweaks t;
  t.axis_lists = true;
  return det::encode(m, o, t);
}

// Frame lines of a map (spec/format.md 2.3), as a map writes them ("%.17g"):
// rotations and translations of every kind, -0, a subnormal, exponent forms,
// counts up to 2^53.
std::string map_frame_lines() {
  const double poses[3][12] = {
      {-0.2739592186924325, 0.021819345900466677, -0.96149376630215733, -0.31057997014702826, 8.33962904204855e-19,
       -0.99974260932269809, -0.02268733357278151, 0.57301224384812977, -0.96174130954921133, -0.0062154041798138156,
       0.27388870414358013, 2.1264800183565487},
      {0, -1, 0, -0.0, 1, 0, 0, 2.5e-5, 0, 0, 1, 1e21},
      {0.8, 0, 0.6, 6.103515625e-05, 0, 1, 0, -4.9406564584124654e-324, -0.6, 0, 0.8, 123456.78900000001}};
  const char* counts[3][3] = {{"10674", "10674", "2"}, {"10700", "955", "167"}, {"9007199254740992", "1", "0"}};
  std::string text;
  char buf[40];
  for (int i = 0; i < 3; ++i) {
    text += std::to_string(i) + " " + counts[i][0] + " " + counts[i][1];
    for (double v : poses[i]) {
      std::snprintf(buf, sizeof buf, " %.17g", v);
      text += buf;
    }
    text += std::string(" ") + counts[i][2] + "\n";
  }
  return text;
}

// The vectors of format 1.3's frame record (spec/format.md 2.3.2 and step
// 21), appended to the manifest after the others were frozen.
void frame_record_vectors() {
  Model map = synthetic(5, 31);
  map.key_values = {{"coordinate_frame", "world"}, {"map_frames", map_frame_lines()},
                    {"map_options", "novelty=1 component_precision=0.5"}, {"map_id", "0123456789abcdef0123456789abcdef"},
                    {"map_revision", "3"}};
  valid("map_frame_record", with_axis_lists(map),
        "format 1.3 map: map_frames as the binary frame record (bit 3, zstd), every key/value packed (bit 1)");
  valid("map_frame_record_raw", with_axis_lists(map, raw_options()), "format 1.3 map, frame record and packed key/values uncompressed");
  fmt::WriteOptions raw;
  raw.compress = false;
  const std::vector<double> rows = det::frame_rows(map.key_values[1].second);
  const det::FrameRecord good = det::encode_frame_rows(rows, raw);
  auto with = [&](const std::string& entry, const std::vector<std::uint8_t>& stored) {
    det::Tweaks t;
    t.axis_lists = true;
    t.frame_record_entry = entry;
    t.frame_record_stored = stored;
    return det::encode(map, {}, t);
  };
  const std::string crc = good.entry.second.substr(good.entry.second.rfind(' ') + 1);
  invalid("frame_record_checksum", with("0 360 360 " + std::to_string(std::stoul(crc) ^ 1), good.stored), "format",
          "checksum_mismatch", "frame record: CRC-32C of the canonical bytes does not match (step 21e)");
  invalid("frame_record_length", with("0 352 352 " + crc, std::vector<std::uint8_t>(good.stored.begin(), good.stored.begin() + 352)),
          "format", "bad_metadata", "frame record: decoded length 352 is not a multiple of 120 (step 21a)");
  invalid("frame_record_raw_length", with("0 361 360 " + crc, good.stored), "format", "bad_layout",
          "frame record: a raw record whose stored length is not its decoded length (step 21c)");
  const det::FrameRecord zstd = det::encode_frame_rows(rows, {});
  invalid("frame_record_overlap", with("1 " + std::to_string(zstd.stored.size() + 1) + " 360 " + crc, zstd.stored),
          "format", "bad_layout", "frame record: one stored byte more reaches into the covariances (step 21c)");
  invalid("frame_record_not_zstd", with("1 360 360 " + crc, good.stored), "format", "decompression_failed",
          "frame record: codec zstd on bytes that are not a zstd frame (step 21d)");
  std::vector<double> half = rows;
  half[15] = 0.5;  // frame 1's n_points
  const det::FrameRecord bad_count = det::encode_frame_rows(half, raw);
  invalid("frame_record_count", with(bad_count.entry.second, bad_count.stored), "format", "bad_metadata",
          "frame record: a point count of 0.5 (step 21f)");
  det::Tweaks no_entry;
  no_entry.axis_lists = true;
  no_entry.compact_maps = false;
  no_entry.minor = 3;
  no_entry.features_required = 0xA;
  no_entry.pack_key_values = true;
  invalid("frame_record_missing", det::encode(map, {}, no_entry), "format", "bad_metadata",
          "features_required bit 3 without a map_frame_record entry (step 21a)");
}

// The vectors of format 1.5 (spec/format.md section 7): files with bit 2 or 3
// as the writer now writes them, without the fixed axis lists.
void axis_lists_optional_vectors() {
  Model map = synthetic(5, 31);
  map.key_values = {{"coordinate_frame", "world"}, {"map_frames", map_frame_lines()},
                    {"map_options", "novelty=1 component_precision=0.5"}, {"map_id", "0123456789abcdef0123456789abcdef"},
                    {"map_revision", "3"}};
  valid("map_without_axis_lists", fmt::to_bytes(map),
        "format 1.5 map (bits 1 and 3, 0xA): the axis lists left out, read as the fixed lists");
  fmt::WriteOptions quant;
  quant.component_precision = 0.5;
  valid("map_quantized_without_axis_lists", fmt::to_bytes(map, quant),
        "format 1.5 map with quantized components (bits 1, 2 and 3, 0xE), without the axis lists");
  valid("quantized_without_axis_lists", fmt::to_bytes(synthetic(12, 21), quant),
        "format 1.5 model with quantized components (bit 2) and no key/values, without the axis lists");
}

// Writes one group of appended vectors into `out` with their manifest entries
// (manifest_additions.json, to append by hand).
int appended(const std::string& out, void (*vectors)()) {
  g_out = out;
  ::mkdir((g_out + "/valid").c_str(), 0755);
  ::mkdir((g_out + "/invalid").c_str(), 0755);
  try {
    vectors();
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
  std::ofstream additions(g_out + "/manifest_additions.json");
  for (std::size_t i = 0; i < g_entries.size(); ++i) additions << g_entries[i] << (i + 1 < g_entries.size() ? ",\n" : "\n");
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 3 && std::string(argv[1]) == "--axis-lists-optional") return appended(argv[2], axis_lists_optional_vectors);
  if (argc == 3 && std::string(argv[1]) == "--frame-record") {
    // Only the frame record's vectors, with their manifest entries.
    return appended(argv[2], frame_record_vectors);
  }
  if (argc != 6) {
    std::cerr << "usage: " << argv[0] << " OUT_DIR DEPTH.u16 GRAY.f32 WIDTH HEIGHT\n";
    return 2;
  }
  try {
    g_out = argv[1];
    ::mkdir((g_out + "/valid").c_str(), 0755);
    ::mkdir((g_out + "/invalid").c_str(), 0755);
    const int width = std::stoi(argv[4]), height = std::stoi(argv[5]);
    const std::size_t npix = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);

    // --- a real fitted model: livingroom frame 0, decimation 5, bandwidth 0.02
    const std::vector<std::uint8_t> depth_raw = read_raw(argv[2], 2 * npix);
    const std::vector<std::uint8_t> gray_raw = read_raw(argv[3], 4 * npix);
    std::vector<std::uint16_t> depth(npix);
    std::vector<float> gray(npix);
    std::memcpy(depth.data(), depth_raw.data(), depth_raw.size());
    std::memcpy(gray.data(), gray_raw.data(), gray_raw.size());
    RgbdView frame{depth.data(), gray.data(), Camera{width, height, 525.0, 525.0, 319.5, 239.5}};
    DepthOptions depth_options;
    depth_options.decimate = 5;
    const PointCloud cloud = backproject(frame, depth_options);
    FitOptions fit_options;
    fit_options.bandwidth = 0.02;
    fit_options.seed = 7;
    fit_options.em.threads = 1;
    fit_options.em.reg_covar = 1e-6;  // explicit: the vectors predate the automatic floors
    const FitResult fit = sogmm::fit(cloud.view(), fit_options);
    Model fitted;
    fitted.gmm = fit.gmm;
    fitted.fit = FitInfo{true, 0.02, 0, fit_options.em.tol, *fit_options.em.reg_covar, fit_options.em.max_iter,
                         fit.em.iterations, fit.em.converged, fit.em.log_likelihood, 7};
    fitted.camera.known = true;
    fitted.camera.camera = frame.camera;
    fitted.camera.decimation = 5;
    fitted.pose = std::array<double, 16>{-0.2739592186924325, 0.021819345900466677, -0.9614937663021573,
                                         -0.31057997014702826, 8.33962904204855e-19, -0.9997426093226981,
                                         -0.02268733357278151, 0.5730122438481298, -0.9617413095492113,
                                         -0.006215404179813816, 0.27388870414358013, 2.1264800183565487,
                                         0.0, 0.0, 0.0, 1.0};  // livingroom/trajectory.log, frame 0
    fitted.producer_name = "sogmm";
    fitted.producer_version = "0.1.0";
    fitted.created_unix_ms = 1767225600000;  // 2026-01-01T00:00:00Z, fixed for reproducibility
    fitted.key_values = {{"source", "livingroom/00000 (Augmented ICL-NUIM via Open3D test data)"}};

    // --- valid vectors
    Model one = synthetic(1, 1);
    one.gmm.weights[0] = 1.0f;
    valid("one_component", fmt::to_bytes(one), "M = 1, no optional metadata tables");
    valid("fitted_livingroom", fmt::to_bytes(fitted),
          "real SOGMM fit of livingroom frame 0 (d = 5, bandwidth 0.02), compressed float32");
    Model all = synthetic(8, 2);
    all.fit = FitInfo{true, 0.0, 8, 1e-3, 1e-6, 100, 23, false, -1.75, 12345678901234567ull};
    all.camera.known = true;
    all.camera.camera = Camera{640, 480, 517.3, 516.5, 318.6, 255.3};
    all.camera.decimation = 4;
    all.camera.depth_scale = 5000.0;
    all.camera.depth_min = 0.2;
    all.camera.depth_max = 4.5;
    all.pose = std::array<double, 16>{0, -1, 0, 1.25, 1, 0, 0, -2.5, 0, 0, 1, 0.75, 0, 0, 0, 1};
    all.created_unix_ms = 1700000000123;
    all.key_values = {{"dataset", "tum"}, {"note", "unicode \xce\xbb \xe2\x9c\x93"}, {"note", "repeated key"},
                      {"", "empty key"}};
    valid("all_metadata", fmt::to_bytes(all), "every metadata field set, repeated and empty keys");
    fmt::WriteOptions f64;
    f64.float64 = true;
    valid("float64", fmt::to_bytes(synthetic(16, 3), f64), "float64 arrays, compressed");
    valid("uncompressed", uncompressed(synthetic(16, 4)), "no filter, no codec, component-major");
    Model full = synthetic(4, 5);
    full.gmm.covariances[16 * 1 + 2] = std::nextafter(full.gmm.covariances[16 * 1 + 2], 1.0f);
    valid("full_covariance_layout", fmt::to_bytes(full), "covariances stored FULL (one is not bit-symmetric)");
    det::Tweaks future;
    future.minor = 1;
    future.features_used = 1u << 5;
    future.unknown_optional_fields = true;
    valid("future_minor", det::encode(synthetic(6, 6), {}, future),
          "format 1.1 with unknown optional fields 20 and 21 and unknown optional feature bit 5");

    // --- invalid vectors
    const Model base = synthetic(6, 9);
    const std::vector<std::uint8_t> good = fmt::to_bytes(base);
    const std::vector<std::uint8_t> raw = uncompressed(base);
    const fmt::FileInfo info = fmt::read_info(good.data(), good.size());
    const fmt::FileInfo raw_info = fmt::read_info(raw.data(), raw.size());
    auto patched = [&](std::vector<std::uint8_t> b, std::size_t off, std::uint8_t v) {
      b[off] = v;
      return b;
    };
    invalid("bad_magic", patched(good, 1, 'X'), "format", "bad_magic", "second signature byte changed");
    std::vector<std::uint8_t> crlf;
    for (std::uint8_t c : good) {
      if (c == '\n') crlf.push_back('\r');
      crlf.push_back(c);
    }
    invalid("text_mode_lf_to_crlf", crlf, "format", "bad_magic", "LF -> CR LF conversion (text-mode transfer)");
    invalid("truncated_empty", {}, "format", "truncated", "empty file");
    invalid("truncated_7", cut(good, 7), "format", "truncated", "cut inside the signature");
    invalid("truncated_20", cut(good, 20), "format", "truncated", "cut inside the header");
    invalid("truncated_in_metadata", cut(good, 32 + info.metadata_length / 2), "format", "truncated",
            "cut inside the metadata");
    invalid("truncated_in_body", cut(good, info.covariances.offset + 5), "format", "truncated",
            "cut inside the covariances");
    invalid("truncated_last_byte", cut(good, good.size() - 1), "format", "truncated", "last byte missing");
    invalid("unknown_major", patched(good, 8, 2), "format", "unsupported_version", "format version 2.0");
    invalid("header_flags", patched(good, 12, 1), "format", "bad_header", "reserved header flags set");
    std::vector<std::uint8_t> trailing = good;
    trailing.insert(trailing.end(), {'S', 'G', 'M', 'M'});
    invalid("trailing_data", trailing, "format", "bad_header", "4 bytes after the declared file length");
    invalid("bad_trailer", patched(good, good.size() - 2, 'X'), "format", "bad_trailer", "end marker damaged");
    det::Tweaks t;
    t.features_required = 1u << 5;
    invalid("unknown_required_feature", det::encode(base, {}, t), "format", "unsupported_feature",
            "features_required has bit 5, unknown in 1.0");
    t = {};
    t.minor = 1;
    t.features_required = 1u << 0;
    invalid("future_minor_required_feature", det::encode(base, {}, t), "format", "unsupported_feature",
            "format 1.1 requiring feature bit 0");
    invalid("metadata_checksum", patched(good, 32 + 40, good[32 + 40] ^ 0x04), "format", "checksum_mismatch",
            "one metadata bit flipped, header CRC not updated");
    invalid("array_checksum", patched(raw, raw_info.means.offset + 6, raw[raw_info.means.offset + 6] ^ 0x01), "format",
            "checksum_mismatch", "one bit of an uncompressed mean flipped");
    t = {};
    t.covariance_crc_xor = 0x00010000;
    invalid("array_checksum_declared", det::encode(base, {}, t), "format", "checksum_mismatch",
            "declared CRC-32C of the covariances wrong");
    std::vector<std::uint8_t> b = good;
    b[32] = 0xF0, b[33] = 0xFF, b[34] = 0xFF, b[35] = 0x00;
    det::refresh_metadata_crc(b);
    invalid("flatbuffer_root_out_of_bounds", b, "format", "bad_metadata", "root table offset beyond the metadata");
    b = good;
    {
      const std::uint32_t root = b[32] | b[33] << 8 | b[34] << 16 | static_cast<std::uint32_t>(b[35]) << 24;
      const std::size_t at = 32 + root;
      b[at] = 0x00, b[at + 1] = 0x00, b[at + 2] = 0x00, b[at + 3] = 0x80;  // soffset to vtable: INT32_MIN
    }
    det::refresh_metadata_crc(b);
    invalid("flatbuffer_vtable_out_of_bounds", b, "format", "bad_metadata", "root vtable offset out of range");
    b = patched(good, 36 + 3, 'X');
    det::refresh_metadata_crc(b);
    invalid("flatbuffer_identifier", b, "format", "bad_metadata", "FlatBuffers file identifier is not SGMM");
    t = {};
    t.dims = 3;
    invalid("dims_3", det::encode(base, {}, t), "format", "bad_metadata", "dims = 3");
    t = {};
    t.means_codec = 7;
    invalid("unknown_codec", det::encode(base, {}, t), "format", "unsupported_encoding", "means codec 7");
    t = {};
    t.n_components = std::uint64_t{1} << 26;
    t.lengths_follow_declared_m = true;
    invalid("declared_size_over_cap", det::encode(base, {}, t), "limit", "limit",
            "M = 2^26 with consistent lengths: 4 GiB declared, over the 1 GiB default cap");
    t = {};
    t.means_offset = info.means.offset + 4;
    invalid("misaligned_offset", det::encode(base, {}, t), "format", "bad_layout", "means offset not a multiple of 8");
    t.means_offset = info.weights.offset;
    invalid("overlapping_arrays", det::encode(base, {}, t), "format", "bad_layout", "means overlap weights");
    const std::vector<std::uint8_t> big = fmt::to_bytes(synthetic(200, 10));
    const fmt::FileInfo big_info = fmt::read_info(big.data(), big.size());
    if (big_info.covariances.codec != "zstd") throw std::runtime_error("expected zstd covariances");
    b = big;
    b[big_info.covariances.offset] ^= 0xFF;  // first zstd frame magic
    invalid("zstd_bad_frame", b, "format", "decompression_failed", "covariances' first zstd frame magic damaged");
    t = {};
    t.n_components = 0;
    invalid("zero_components", det::encode(base, {}, t), "invalid_data", "empty", "M = 0");
    t.n_components = 5;
    invalid("length_mismatch", det::encode(base, {}, t), "invalid_data", "length_mismatch",
            "M = 5 declared, arrays hold 6 components");
    det::Tweaks nv;
    nv.validate = false;
    Model bad = base;
    bad.gmm.means[9] = std::numeric_limits<float>::quiet_NaN();
    invalid("nan_mean", det::encode(bad, {}, nv), "numeric", "non_finite", "a mean coordinate is NaN");
    bad = base;
    bad.gmm.covariances[16 * 4 + 5] = std::numeric_limits<float>::infinity();
    invalid("inf_covariance", det::encode(bad, {}, nv), "numeric", "non_finite", "a covariance diagonal is +Inf");
    bad = base;
    for (int i = 0; i < 4; ++i) bad.gmm.covariances[16 * 3 + 5 * i] = -bad.gmm.covariances[16 * 3 + 5 * i];
    invalid("not_positive_definite", det::encode(bad, {}, nv), "numeric", "not_spd",
            "component 3's covariance is negative definite");
    bad = base;
    bad.gmm.covariances[16 * 2 + 1] = bad.gmm.covariances[16 * 2 + 4] =
        2.0f * std::sqrt(bad.gmm.covariances[16 * 2] * bad.gmm.covariances[16 * 2 + 5]);
    invalid("not_positive_definite_offdiag", det::encode(bad, {}, nv), "numeric", "not_spd",
            "positive diagonal, correlation 2 between x and y");
    bad = base;
    bad.gmm.covariances[16 * 1 + 3] += 0.001f;
    invalid("not_symmetric", det::encode(bad, {}, nv), "numeric", "not_symmetric",
            "FULL layout, covariance 1 asymmetric beyond 1e-5 relative");
    bad = base;
    bad.gmm.weights[0] *= 1.5f;
    invalid("weights_sum", det::encode(bad, {}, nv), "numeric", "bad_weights", "weights sum to about 1.1");
    bad = base;
    bad.gmm.weights[1] += bad.gmm.weights[0] + 0.125f;
    bad.gmm.weights[0] = -0.125f;
    invalid("negative_weight", det::encode(bad, {}, nv), "numeric", "bad_weights", "a negative weight, sum 1");
    bad = base;
    bad.pose = std::array<double, 16>{2, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    invalid("pose_not_rigid", det::encode(bad, {}, nv), "invalid_data", "bad_pose", "pose scales x by 2");

    // --- appended with issue 13 (metadata strings, F64 values rounded to float32)
    det::Tweaks share;
    share.share_strings = true;
    Model shared = synthetic(3, 11);
    shared.key_values = {{"camera", "kinect v1"}, {"rig", "kinect v1"}, {"spare", "kinect v1"}};
    valid("shared_strings", det::encode(shared, {}, share),
          "three values share one string; the strings total fewer bytes than the block");
    Model controls = synthetic(3, 12);
    controls.producer_name = "sogmm\x1b]0;title\x07";
    controls.key_values = {{"note", "\x1b[2J\x1b[31mred\r\nforged: line\xe2\x80\xae\xc2\x9b"}};
    valid("control_characters", fmt::to_bytes(controls),
          "terminal escape sequences, CR LF, U+202E and U+009B in strings: valid UTF-8 (tools escape them)");
    bad = base;
    bad.key_values = {{"note", "caf\xe9"}};
    invalid("string_not_utf8", det::encode(bad, {}, nv), "format", "bad_metadata",
            "a key/value value in Latin-1 (byte 0xE9), not UTF-8");
    bad = base;
    bad.key_values = {{"\xed\xa0\x80", "v"}};
    invalid("string_surrogate", det::encode(bad, {}, nv), "format", "bad_metadata",
            "a key holding the UTF-16 surrogate U+D800 (CESU-8), not UTF-8");
    bad = base;
    bad.producer_name = "sogmm\xc0\xaf";
    invalid("string_overlong", det::encode(bad, {}, nv), "format", "bad_metadata",
            "producer name with an overlong encoding of '/'");
    bad = base;
    bad.key_values = {{"note", std::string("visible\0hidden", 14)}};
    invalid("string_nul", det::encode(bad, {}, nv), "format", "bad_metadata", "a key/value value with an embedded NUL");
    bad = base;
    bad.key_values.assign(64, {"k", std::string(1000, 'x')});
    det::Tweaks share_nv = share;
    share_nv.validate = false;
    invalid("shared_strings_over_block", det::encode(bad, {}, share_nv), "format", "bad_metadata",
            "64 pairs sharing one key and one 1000-byte value: 64 KB of strings from a 2 KB block");
    fmt::WriteOptions raw64;
    raw64.float64 = true;
    raw64.compress = false;
    b = fmt::to_bytes(synthetic(2, 13), raw64);
    const double tiny_diagonal[10] = {1e-50, 0, 0, 0, 1e-3, 0, 0, 1e-3, 0, 1e-3};  // packed, component 0
    for (int t = 0; t < 10; ++t) det::patch_f64_value(b, det::kCovariances, static_cast<std::uint64_t>(t), tiny_diagonal[t]);
    invalid("f64_underflows_float32", b, "numeric", "not_spd",
            "float64 covariance diag(1e-50, 1e-3, 1e-3, 1e-3): positive definite in binary64, singular once rounded to "
            "binary32");

    // Quantized components (spec/format.md 5.7, format 1.4, feature bit 2).
    fmt::WriteOptions quant;
    quant.component_precision = 0.5;
    valid("quantized_components", with_axis_lists(synthetic(12, 21), quant),
          "format 1.4, feature bit 2: twelve components stored as the integer codes of section 5.7 (zstd); the dump "
          "is the float32 model the decoding formulas give");
    quant.compress = false;
    const std::vector<std::uint8_t> raw_codes = with_axis_lists(synthetic(5, 22), quant);
    valid("quantized_components_raw", raw_codes,
          "format 1.4, feature bit 2: five components' codes stored raw (column-major, byte-stream split, no codec)");
    {
      // Covariance code f (column 0) of component 1 set to 17: codes are
      // column-major and byte-stream split, so its 4 bytes are at n i + 1.
      const fmt::FileInfo info = fmt::read_info(raw_codes.data(), raw_codes.size());
      std::vector<std::uint8_t> bad_f = raw_codes;
      const std::uint64_t n = 5 * 14;
      const std::uint32_t z = 2 * 17;  // zigzag(17)
      for (int byte = 0; byte < 4; ++byte) bad_f[info.covariances.offset + byte * n + 1] = static_cast<std::uint8_t>(z >> (8 * byte));
      invalid("quantized_code_out_of_range", bad_f, "invalid_data", "bad_quantization",
              "covariance code f of component 1 is 17, above its range [0, 16] (section 5.7, step 17b)");
    }
    {
      // The codes of a quantized file declared without feature bit 2: written
      // with the bit, then the bit cleared in the metadata (its CRC refreshed).
      std::vector<std::uint8_t> b2 = raw_codes;
      auto* root = sogmm::fb::GetMutableSogmmFile(b2.data() + 32);
      if (!root->mutate_features_required(0)) throw std::runtime_error("features_required not present");
      det::refresh_metadata_crc(b2);
      invalid("quantized_filter_without_feature", b2, "format", "unsupported_encoding",
              "arrays with filter 2 (QUANTIZED) in a file whose features_required lacks bit 2 (step 12)");
    }

    std::ofstream manifest(g_out + "/manifest.json");
    manifest << "{\n  \"format\": \"sogmm-conformance\",\n  \"manifest_version\": 1,\n"
             << "  \"format_version\": \"1.0\",\n"
             << "  \"note\": \"Frozen. Generated once by generator/generate_vectors.cpp; see README.md.\",\n"
             << "  \"vectors\": [\n";
    for (std::size_t i = 0; i < g_entries.size(); ++i) manifest << g_entries[i] << (i + 1 < g_entries.size() ? ",\n" : "\n");
    manifest << "  ]\n}\n";
    std::cout << g_entries.size() << " vectors written to " << g_out << " (fitted model: M = " << fitted.gmm.size()
              << ", " << fmt::to_bytes(fitted).size() << " bytes)\n";
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
