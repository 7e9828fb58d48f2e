// sogmm-inspect: look inside a .sogmm file.
//
//   sogmm-inspect FILE                 summary: version, producer, metadata, M, sizes,
//                                      weight and covariance statistics, checksum status
//   sogmm-inspect --metadata FILE      header and metadata only (nothing decompressed)
//   sogmm-inspect --json FILE          canonical JSON dump (spec/format.md section 10)
//   sogmm-inspect --components [RANGE] FILE
//                                      per-component values; RANGE is I, I:J (J exclusive) or I:
//   sogmm-inspect --verify FILE        full verification; prints "ok" or one line with the reason
//
// Exit codes: 0 ok, 2 usage, 3 invalid file, 4 I/O error.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <iostream>
#include <string>
#include <vector>

#include <Eigen/Eigenvalues>

#include "sogmm/format.hpp"
#include "sogmm/map_delta.hpp"
#include "sogmm/map_delta_file.hpp"

namespace {

namespace fmt = sogmm::format;

int usage(const std::string& msg = {}) {
  if (!msg.empty()) std::cerr << "sogmm-inspect: " << msg << "\n";
  std::cerr << "usage: sogmm-inspect [--metadata | --json | --verify | --components [RANGE]] FILE\n"
               "  (no option)        summary with statistics\n"
               "  --metadata         header and metadata only (no decompression)\n"
               "  --json             canonical JSON dump of the whole file\n"
               "  --components RANGE per-component values; RANGE = I, I:J or I: (default: all)\n"
               "  --verify           verify everything; exit 0 and print \"ok\", or exit 3 with the reason\n"
               "exit codes: 0 ok, 2 usage, 3 invalid file, 4 I/O error\n";
  return 2;
}

int error_exit(const sogmm::Error& e, const std::string& path) {
  std::cerr << "sogmm-inspect: " << path << ": " << e.what() << "\n";
  return e.code() == sogmm::ErrorCode::Io ? 4 : 3;
}

std::string iso_time(std::int64_t ms) {
  if (ms == 0) return "unknown";
  const std::time_t s = static_cast<std::time_t>(ms / 1000);
  std::tm tm{};
  gmtime_r(&s, &tm);
  char buf[64];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%S", &tm);
  char out[80];
  std::snprintf(out, sizeof out, "%s.%03dZ", buf, static_cast<int>(((ms % 1000) + 1000) % 1000));
  return out;
}

struct Stats {
  double min = 0, median = 0, max = 0;
};
Stats stats(std::vector<double> v) {
  Stats s;
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  s.min = v.front();
  s.max = v.back();
  const std::size_t n = v.size();
  s.median = n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
  return s;
}

// A metadata string as printed: the backslash and every control or
// direction-changing code point (C0, DEL, C1, line/paragraph separators, bidi
// embeddings, overrides and isolates) escaped as \xNN or \uNNNN, so that a file
// cannot drive the terminal (escape sequences), reorder what is shown or fake
// lines of this output. Strings read from a file are valid UTF-8 (the reader
// checks), so code points can be decoded without further checks.
std::string printable(const std::string& s) {
  std::string out;
  for (std::size_t i = 0; i < s.size();) {
    const auto b = static_cast<unsigned char>(s[i]);
    const std::size_t len = b < 0x80 ? 1 : b < 0xE0 ? 2 : b < 0xF0 ? 3 : 4;
    std::uint32_t cp = len == 1 ? b : b & (0x7F >> len);
    for (std::size_t k = 1; k < len && i + k < s.size(); ++k) cp = (cp << 6) | (s[i + k] & 0x3F);
    const bool escape = cp < 0x20 || (cp >= 0x7F && cp <= 0x9F) || (cp >= 0x2028 && cp <= 0x202E) ||
                        (cp >= 0x2066 && cp <= 0x2069);
    char buf[16];
    if (cp == '\\') {
      out += "\\\\";
    } else if (escape) {
      if (cp < 0x80) {
        std::snprintf(buf, sizeof buf, "\\x%02x", static_cast<unsigned>(cp));
      } else {
        std::snprintf(buf, sizeof buf, "\\u%04x", static_cast<unsigned>(cp));
      }
      out += buf;
    } else {
      out.append(s, i, len);
    }
    i += len;
  }
  return out;
}

void print_array(const char* name, const fmt::ArrayInfo& a) {
  std::printf("  %-12s %s %s %s %s  stored %llu B, decoded %llu B, crc32c %08x\n", name, a.dtype.c_str(),
              a.order.c_str(), a.filter.c_str(), a.codec.c_str(), static_cast<unsigned long long>(a.stored_length),
              static_cast<unsigned long long>(a.decoded_length), a.crc32c);
}

// `m` holds the metadata (info.metadata after read_info_file, the model after load).
void print_metadata(const fmt::FileInfo& info, const sogmm::Model& m) {
  std::printf("format version      %u.%u\n", info.format_major, info.format_minor);
  std::printf("producer            %s %s\n", printable(m.producer_name).c_str(),
              printable(m.producer_version).c_str());
  std::printf("created             %s\n", iso_time(m.created_unix_ms).c_str());
  std::printf("components (M)      %llu\n", static_cast<unsigned long long>(info.n_components));
  std::printf("support size        %llu points\n", static_cast<unsigned long long>(m.gmm.support_size));
  std::printf("file size           %llu bytes (metadata %llu), %.2f bytes per component\n",
              static_cast<unsigned long long>(info.file_length), static_cast<unsigned long long>(info.metadata_length),
              static_cast<double>(info.file_length) / static_cast<double>(info.n_components));
  const std::uint64_t arrays = info.weights.stored_length + info.means.stored_length + info.covariances.stored_length;
  std::printf("arrays              %llu bytes, %.2f bytes per component (covariances %s)\n",
              static_cast<unsigned long long>(arrays),
              static_cast<double>(arrays) / static_cast<double>(info.n_components), info.covariance_layout.c_str());
  print_array("weights", info.weights);
  print_array("means", info.means);
  print_array("covariances", info.covariances);
  std::printf("features            required 0x%llx, used 0x%llx\n",
              static_cast<unsigned long long>(info.features_required),
              static_cast<unsigned long long>(info.features_used));
  std::printf("axes                x, y, z [m], gray [0, 1]\n");
  if (m.fit.known) {
    const sogmm::FitInfo& f = m.fit;
    std::printf("fit                 bandwidth %g, K requested %llu, tol %g, reg_covar %g, max_iter %d\n", f.bandwidth,
                static_cast<unsigned long long>(f.n_components_requested), f.tol, f.reg_covar, f.max_iter);
    std::printf("                    %d iterations, %s, log-likelihood %.6g, seed %llu\n", f.n_iter,
                f.converged ? "converged" : "not converged", f.log_likelihood, static_cast<unsigned long long>(f.seed));
  } else {
    std::printf("fit                 unknown\n");
  }
  if (m.camera.known) {
    const sogmm::CameraInfo& c = m.camera;
    std::printf("camera              %dx%d fx %g fy %g cx %g cy %g, decimation %d, depth scale %g, depth (%g, %g] m\n",
                c.camera.width, c.camera.height, c.camera.fx, c.camera.fy, c.camera.cx, c.camera.cy, c.decimation,
                c.depth_scale, c.depth_min, c.depth_max);
  } else {
    std::printf("camera              unknown\n");
  }
  if (m.pose) {
    const auto& p = *m.pose;
    for (int r = 0; r < 4; ++r) {
      std::printf("%s[% .6f % .6f % .6f % .6f]\n", r == 0 ? "pose (camera->world) " : "                     ",
                  p[4 * r], p[4 * r + 1], p[4 * r + 2], p[4 * r + 3]);
    }
  } else {
    std::printf("pose                unknown\n");
  }
  for (const auto& kv : m.key_values) {
    std::printf("key/value           %s = %s\n", printable(kv.first).c_str(), printable(kv.second).c_str());
  }
}

void print_statistics(const sogmm::Model& model) {
  const sogmm::Gmm& g = model.gmm;
  const std::size_t m = g.size();
  std::vector<double> w(g.weights.begin(), g.weights.end()), emin, emed, emax, cond;
  for (std::size_t k = 0; k < m; ++k) {
    Eigen::Matrix4d c = Eigen::Map<const Eigen::Matrix<float, 4, 4, Eigen::RowMajor>>(g.covariance(k)).cast<double>();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> es(c, Eigen::EigenvaluesOnly);
    const Eigen::Vector4d ev = es.eigenvalues();  // ascending
    emin.push_back(ev[0]);
    emax.push_back(ev[3]);
    emed.push_back(0.5 * (ev[1] + ev[2]));
    cond.push_back(ev[3] / ev[0]);
  }
  const Stats sw = stats(w), s0 = stats(emin), s3 = stats(emax), sc = stats(cond);
  std::printf("weights             min %.6g, median %.6g, max %.6g\n", sw.min, sw.median, sw.max);
  std::printf("smallest eigenvalue min %.6g, median %.6g, max %.6g\n", s0.min, s0.median, s0.max);
  std::printf("largest eigenvalue  min %.6g, median %.6g, max %.6g\n", s3.min, s3.median, s3.max);
  std::printf("condition number    min %.6g, median %.6g, max %.6g\n", sc.min, sc.median, sc.max);
  (void)emed;
}

bool parse_range(const std::string& s, std::size_t m, std::size_t* lo, std::size_t* hi) {
  try {
    const std::size_t colon = s.find(':');
    std::size_t pos = 0;
    if (colon == std::string::npos) {
      *lo = std::stoul(s, &pos);
      if (pos != s.size()) return false;
      *hi = *lo + 1;
    } else {
      const std::string a = s.substr(0, colon), b = s.substr(colon + 1);
      *lo = a.empty() ? 0 : std::stoul(a, &pos);
      if (!a.empty() && pos != a.size()) return false;
      *hi = b.empty() ? m : std::stoul(b, &pos);
      if (!b.empty() && pos != b.size()) return false;
    }
  } catch (const std::exception&) {
    return false;
  }
  *hi = std::min(*hi, m);
  return *lo < *hi;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  std::string mode = "summary", range, path;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "-h" || a == "--help") {
      usage();
      return 0;
    }
    if (a == "--json" || a == "--verify" || a == "--metadata") {
      if (mode != "summary") return usage("only one of --metadata, --json, --verify, --components");
      mode = a.substr(2);
    } else if (a == "--components") {
      if (mode != "summary") return usage("only one of --metadata, --json, --verify, --components");
      mode = "components";
      // An optional RANGE: the next argument if another argument (FILE) follows it.
      if (i + 2 < args.size() + 0 && args[i + 1].rfind("--", 0) != 0) range = args[++i];
    } else if (!a.empty() && a[0] == '-' && a != "-") {
      return usage("unknown option " + a);
    } else {
      if (!path.empty()) return usage("more than one FILE");
      path = a;
    }
  }
  if (path.empty()) return usage("no FILE given");

  try {
    if (mode == "metadata") {
      const fmt::FileInfo info = fmt::read_info_file(path);
      print_metadata(info, info.metadata);
      std::printf("checksums           metadata verified; arrays not read\n");
      return 0;
    }
    // A map delta (spec/format.md 2.5: bit 0 and its keys, or bit 0 and bit 1,
    // its keys packed, 2.5.1) is verified by the delta rules and shown as
    // the model form it is stored in (delta keys included, unpacked). Bit 0 without the keys is no delta: read as a model,
    // it is refused as such (unsupported_feature). The probe's metadata is
    // freed before the full read (section 8's memory bound).
    bool delta = false;
    {
      const fmt::FileInfo probe = fmt::read_info_file(path);
      delta = (probe.features_required & 1u) != 0 &&
              ((probe.features_required & 2u) != 0 || sogmm::find_value(probe.metadata, sogmm::kDeltaOpsKey) != nullptr);
    }
    fmt::FileInfo info;
    sogmm::Model model;
    if (delta) {
      model = sogmm::delta_to_model(fmt::load_delta(path));
      info = fmt::read_info_file(path);
      info.metadata = sogmm::Model{};
    } else {
      model = fmt::load(path, {}, &info);
    }
    if (mode == "verify") {
      std::printf(delta ? "ok (map delta)\n" : "ok\n");
      return 0;
    }
    if (mode == "json") {
      std::fputs(fmt::to_canonical_json(model, &info).c_str(), stdout);
      return 0;
    }
    if (mode == "components") {
      std::size_t lo = 0, hi = model.gmm.size();
      if (!range.empty() && !parse_range(range, model.gmm.size(), &lo, &hi)) {
        return usage("bad RANGE '" + range + "' for M = " + std::to_string(model.gmm.size()));
      }
      for (std::size_t k = lo; k < hi; ++k) {
        const float* mu = model.gmm.mean(k);
        const float* c = model.gmm.covariance(k);
        std::printf("component %zu  weight %.9g\n  mean [%.9g %.9g %.9g %.9g]\n", k, model.gmm.weights[k], mu[0], mu[1],
                    mu[2], mu[3]);
        for (int r = 0; r < 4; ++r) {
          std::printf("  %s[% .9g % .9g % .9g % .9g]\n", r == 0 ? "cov " : "    ", c[4 * r], c[4 * r + 1],
                      c[4 * r + 2], c[4 * r + 3]);
        }
      }
      return 0;
    }
    print_metadata(info, model);
    if (delta) {
      std::printf("map delta           revision %s -> %s, %zu explicit components\n",
                  sogmm::find_value(model, sogmm::kDeltaBaseRevisionKey)->c_str(),
                  sogmm::find_value(model, sogmm::kDeltaRevisionKey)->c_str(), model.gmm.size());
      std::printf("checksums           all verified (metadata and %d arrays); steps checked by a receiver\n", 3);
      return 0;
    }
    print_statistics(model);
    std::printf("checksums           all verified (metadata and %d arrays)\n", 3);
    return 0;
  } catch (const sogmm::Error& e) {
    if (mode == "verify") {
      std::printf("invalid: %s\n", e.what());
      return e.code() == sogmm::ErrorCode::Io ? 4 : 3;
    }
    return error_exit(e, path);
  } catch (const std::exception& e) {
    std::cerr << "sogmm-inspect: " << path << ": " << e.what() << "\n";
    return 3;
  }
}
