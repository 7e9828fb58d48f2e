// Quantized components (spec/format.md section 5.7, format 1.4): the bound
// every decoded component keeps against the original, the file's version and
// feature bit, round trips, and hostile codes refused by name.
//
// Every check here is integer or binary64 arithmetic of the format library,
// which is built with -ffp-contract=off and uses no SIMD kernel: the decoded
// bits, and so these bounds, are the same under SOGMM_ISA=sse2, avx2 and the
// default (AVX-512).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "internal.hpp"
#include "sogmm/format.hpp"
#include "sogmm_generated.h"
#include "test_support.hpp"

namespace sogmm::format {
namespace {

// Cholesky of a symmetric 4x4 (row-major, binary64); false when a pivot is not > 0.
bool cholesky(const double* a, double* l) {
  std::memset(l, 0, 16 * sizeof(double));
  for (int j = 0; j < 4; ++j) {
    double d = a[4 * j + j];
    for (int k = 0; k < j; ++k) d -= l[4 * j + k] * l[4 * j + k];
    if (!(d > 0)) return false;
    l[4 * j + j] = std::sqrt(d);
    for (int i = j + 1; i < 4; ++i) {
      double s = a[4 * i + j];
      for (int k = 0; k < j; ++k) s -= l[4 * i + k] * l[4 * j + k];
      l[4 * i + j] = s / l[4 * j + j];
    }
  }
  return true;
}

// x = L^-1 b for lower-triangular L.
void forward(const double* l, const double* b, double* x) {
  for (int i = 0; i < 4; ++i) {
    double s = b[i];
    for (int k = 0; k < i; ++k) s -= l[4 * i + k] * x[k];
    x[i] = s / l[4 * i + i];
  }
}

// The bound of round_to_precision, checked without the encoder's eigen
// solver: every eigenvalue of W = L^-1 S' L^-T lies in [1 - p, 1 + p] iff
// W - (1 - p) I and (1 + p) I - W are positive semi-definite; tested as
// positive definite after widening the interval by 1e-9 (W's rounding).
struct Bound {
  bool covariance = false;
  double mean_sigmas = 0;
};
Bound check_component(const float* s0, const float* m0, const float* s1, const float* m1, double p) {
  double a[16], l[16], w[16];
  for (int i = 0; i < 16; ++i) a[i] = s0[i];
  EXPECT_TRUE(cholesky(a, l));
  for (int j = 0; j < 4; ++j) {  // column j of L^-1 S' ...
    double col[4], x[4];
    for (int i = 0; i < 4; ++i) col[i] = s1[4 * i + j];
    forward(l, col, x);
    for (int i = 0; i < 4; ++i) w[4 * i + j] = x[i];
  }
  for (int i = 0; i < 4; ++i) {  // ... then (L^-1 (L^-1 S')^T)
    double row[4], x[4];
    for (int j = 0; j < 4; ++j) row[j] = w[4 * i + j];
    forward(l, row, x);
    for (int j = 0; j < 4; ++j) a[4 * i + j] = x[j];
  }
  double lo[16], hi[16], tmp[16];
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) {
      const double sym = 0.5 * (a[4 * i + j] + a[4 * j + i]);
      const double id = i == j ? 1.0 : 0.0;
      lo[4 * i + j] = sym - (1 - p - 1e-9) * id;
      hi[4 * i + j] = (1 + p + 1e-9) * id - sym;
    }
  }
  Bound b;
  b.covariance = cholesky(lo, tmp) && cholesky(hi, tmp);
  double d[4], x[4];
  for (int i = 0; i < 4; ++i) d[i] = static_cast<double>(m1[i]) - m0[i];
  for (int i = 0; i < 16; ++i) a[i] = s0[i];
  cholesky(a, l);
  forward(l, d, x);
  b.mean_sigmas = std::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2] + x[3] * x[3]);
  return b;
}

// Components like a map's: random rotations, surfaces as thin as 1/100 of
// their extent (condition numbers up to 10^4), gray correlated with position,
// weights over four decades. Seeded.
Model thin_components(std::size_t m, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::normal_distribution<double> n(0, 1);
  Model model;
  Gmm& g = model.gmm;
  g.resize(m);
  g.support_size = 1000;
  double total = 0;
  for (std::size_t k = 0; k < m; ++k) {
    g.weights[k] = static_cast<float>(std::pow(10.0, -4 * u(rng)));
    total += g.weights[k];
    // A random rotation from a normalised Gaussian quaternion.
    double q[4], qn = 0;
    for (double& c : q) {
      c = n(rng);
      qn += c * c;
    }
    for (double& c : q) c /= std::sqrt(qn);
    const double r[9] = {1 - 2 * (q[2] * q[2] + q[3] * q[3]), 2 * (q[1] * q[2] - q[0] * q[3]),
                         2 * (q[1] * q[3] + q[0] * q[2]),     2 * (q[1] * q[2] + q[0] * q[3]),
                         1 - 2 * (q[1] * q[1] + q[3] * q[3]), 2 * (q[2] * q[3] - q[0] * q[1]),
                         2 * (q[1] * q[3] - q[0] * q[2]),     2 * (q[2] * q[3] + q[0] * q[1]),
                         1 - 2 * (q[1] * q[1] + q[2] * q[2])};
    const double big = 0.01 + 0.1 * u(rng);
    const double sd[3] = {big, big * (0.2 + 0.8 * u(rng)), big * std::pow(10.0, -2 * u(rng))};
    double s[16] = {};
    for (int a = 0; a < 3; ++a) {
      for (int b = 0; b < 3; ++b) {
        for (int i = 0; i < 3; ++i) s[4 * a + b] += r[3 * a + i] * sd[i] * sd[i] * r[3 * b + i];
      }
    }
    const double slope[3] = {n(rng), n(rng), n(rng)}, v = std::pow(10.0, -2 - 3 * u(rng));
    double sb[3] = {}, bsb = 0;
    for (int a = 0; a < 3; ++a) {
      for (int b = 0; b < 3; ++b) sb[a] += s[4 * a + b] * slope[b];
      bsb += slope[a] * sb[a];
    }
    for (int a = 0; a < 3; ++a) s[4 * a + 3] = s[12 + a] = sb[a];
    s[15] = v + bsb;
    for (int i = 0; i < 16; ++i) g.covariances[16 * k + i] = static_cast<float>(s[i]);
    for (int i = 0; i < 3; ++i) g.means[4 * k + i] = static_cast<float>(4 * (u(rng) - 0.5));
    g.means[4 * k + 3] = static_cast<float>(u(rng));
  }
  for (std::size_t k = 0; k < m; ++k) g.weights[k] = static_cast<float>(g.weights[k] / total);
  return model;
}

// Keeps the components a reader accepts (float rounding of the thinnest may not be SPD).
Model valid_part(const Model& in) {
  Model out = in;
  Gmm& g = out.gmm;
  std::size_t kept = 0;
  double total = 0;
  for (std::size_t k = 0; k < in.gmm.size(); ++k) {
    double s[16];
    for (int i = 0; i < 16; ++i) s[i] = in.gmm.covariances[16 * k + i];
    if (!stored_cholesky(s)) continue;
    g.weights[kept] = in.gmm.weights[k];
    std::copy_n(in.gmm.means.data() + 4 * k, 4, g.means.data() + 4 * kept);
    std::copy_n(in.gmm.covariances.data() + 16 * k, 16, g.covariances.data() + 16 * kept);
    total += g.weights[kept++];
  }
  g.resize(kept);
  for (float& w : g.weights) w = static_cast<float>(w / total);
  return out;
}

TEST(QuantizedComponents, EveryDecodedComponentKeepsTheBound) {
  const Model model = valid_part(thin_components(400, 7));
  ASSERT_GT(model.gmm.size(), 350u);
  for (const double p : {0.5, 0.25, 0.05}) {
    WriteOptions w;
    w.component_precision = p;
    const std::vector<std::uint8_t> file = to_bytes(model, w);
    const FileInfo info = read_info(file.data(), file.size());
    ASSERT_EQ(info.features_required, 4u) << "p = " << p << ": the writer fell back to floats";
    EXPECT_EQ(info.format_minor, 5);  // 1.4 with the axis lists left out (spec/format.md section 7)
    EXPECT_EQ(info.covariances.filter, "quantized");
    const Model back = from_bytes(file.data(), file.size());
    ASSERT_EQ(back.gmm.size(), model.gmm.size());
    double worst_mean = 0, worst_weight = 0;
    for (std::size_t k = 0; k < model.gmm.size(); ++k) {
      const Bound b = check_component(model.gmm.covariance(k), model.gmm.mean(k), back.gmm.covariance(k),
                                      back.gmm.mean(k), p);
      EXPECT_TRUE(b.covariance) << "p = " << p << ", component " << k;
      EXPECT_LE(b.mean_sigmas, p) << "p = " << p << ", component " << k;
      worst_mean = std::max(worst_mean, b.mean_sigmas);
      worst_weight = std::max(worst_weight, std::abs(std::log(static_cast<double>(back.gmm.weights[k]) / model.gmm.weights[k])));
    }
    // Weights: each within 1 +- 2^-4 before the common division, whose sum
    // (of the original weights, summing to 1) is then within 1 +- 2^-4 too, so
    // |log(w' / w)| <= log(1 + 2^-4) - log(1 - 2^-4).
    EXPECT_LE(worst_weight, std::log((1 + 1.0 / 16) / (1 - 1.0 / 16)));
    EXPECT_GT(worst_mean, 0.25 * p) << "the grids are as coarse as the bound allows";
    if (p == 0.5) {
      EXPECT_LT(file.size(), 24u * model.gmm.size() + 2000) << "a few bytes per component";
    }
  }
}

// Saving a model read from a quantized file again gives the same model: the
// encoder finds the codes it was decoded from (section 5.7, "Writing a
// decoded model again"), so a map loaded, extended and saved again at the
// same precision does not move its old components by up to the precision per
// save. The exception is a component with two equal spatial eigenvalues whose
// undetermined axes lie beyond the search (tilt or turn finer than 2^-5):
// quantized afresh within the bound, at most 1% here (1-4% of the real maps
// measured). Without the recovery 68-75% of these components come back
// unchanged (a fresh search often lands on the same grids), the rest moved.
std::size_t unchanged(const Model& a, const Model& b) {
  std::size_t same = 0;
  for (std::size_t k = 0; k < a.gmm.size(); ++k) {
    same += std::memcmp(a.gmm.mean(k), b.gmm.mean(k), 4 * sizeof(float)) == 0 &&
            std::memcmp(a.gmm.covariance(k), b.gmm.covariance(k), 16 * sizeof(float)) == 0;
  }
  return same;
}

TEST(QuantizedComponents, SavingADecodedModelAgainKeepsItBitForBit) {
  const Model model = valid_part(thin_components(400, 17));
  for (const double p : {0.5, 0.25, 0.05}) {
    WriteOptions w;
    w.component_precision = p;
    const std::vector<std::uint8_t> first = to_bytes(model, w);
    const Model once = from_bytes(first.data(), first.size());
    const std::vector<std::uint8_t> second = to_bytes(once, w);
    const Model twice = from_bytes(second.data(), second.size());
    ASSERT_EQ(twice.gmm.size(), once.gmm.size());
    EXPECT_GE(unchanged(once, twice), once.gmm.size() - once.gmm.size() / 100) << "p = " << p;
    EXPECT_EQ(std::memcmp(once.gmm.weights.data(), twice.gmm.weights.data(), once.gmm.size() * sizeof(float)), 0)
        << "p = " << p;
    // A finer precision keeps the decoded model too (zero error meets any bound).
    WriteOptions finer;
    finer.component_precision = p / 4;
    const std::vector<std::uint8_t> third = to_bytes(once, finer);
    EXPECT_GE(unchanged(once, from_bytes(third.data(), third.size())), once.gmm.size() - once.gmm.size() / 100)
        << "p = " << p;
  }
}

// The weights of a small model: the decoder divides the codes' mini-floats by
// their sum, which with few components can be far enough from 1 that rounding
// the decoded weights afresh picks other codes (it does for these six
// weights, found by a search over random small models: about 1 in 100 of
// them), so the encoder looks for the original codes.
TEST(QuantizedComponents, SavingADecodedSmallModelAgainKeepsItsWeights) {
  Model model = valid_part(thin_components(6, 3));
  ASSERT_EQ(model.gmm.size(), 6u);
  const float weights[6] = {0.05905437f, 0.04014548f, 0.04425246f, 0.24113953f, 0.02212305f, 0.59328514f};
  std::copy_n(weights, 6, model.gmm.weights.data());
  WriteOptions w;
  w.component_precision = 0.5;
  const std::vector<std::uint8_t> first = to_bytes(model, w);
  const Model once = from_bytes(first.data(), first.size());
  const std::vector<std::uint8_t> second = to_bytes(once, w);
  const Model twice = from_bytes(second.data(), second.size());
  for (std::size_t k = 0; k < 6; ++k) EXPECT_EQ(once.gmm.weights[k], twice.gmm.weights[k]) << "component " << k;
}

TEST(QuantizedComponents, FloatWritesStayBitExactAndQuantizedReadsAreStable) {
  const Model model = test::synthetic_model(40, 3);
  const std::vector<std::uint8_t> plain = to_bytes(model);
  EXPECT_EQ(read_info(plain.data(), plain.size()).features_required, 0u);
  EXPECT_TRUE(test::bit_equal(from_bytes(plain.data(), plain.size()), model));
  WriteOptions w;
  w.component_precision = 0.5;
  const std::vector<std::uint8_t> q = to_bytes(model, w);
  const Model once = from_bytes(q.data(), q.size());
  // The decoded model, saved as floats, reads back bit for bit; metadata kept.
  const std::vector<std::uint8_t> again = to_bytes(once);
  EXPECT_TRUE(test::bit_equal(from_bytes(again.data(), again.size()), once));
  EXPECT_EQ(once.producer_name, model.producer_name);
  EXPECT_EQ(once.key_values, model.key_values);
  // Raw codes (no zstd) decode to the same model.
  w.compress = false;
  const std::vector<std::uint8_t> raw = to_bytes(model, w);
  EXPECT_TRUE(test::bit_equal(from_bytes(raw.data(), raw.size()), once));
}

// A file of raw codes (compress = false) with code (component k, column c) of
// array `which` set to `value`: column-major, byte-stream split (section 5.7).
std::vector<std::uint8_t> with_code(std::vector<std::uint8_t> file, int which, std::uint64_t k, std::uint64_t c,
                                    std::int32_t value) {
  const FileInfo info = read_info(file.data(), file.size());
  const ArrayInfo& a = which == 0 ? info.weights : which == 1 ? info.means : info.covariances;
  const std::uint64_t m = info.n_components, cols = which == 0 ? 1 : which == 1 ? 5 : 14;
  const std::uint64_t n = m * cols, i = c * m + k;
  const std::uint32_t z = (static_cast<std::uint32_t>(value) << 1) ^ static_cast<std::uint32_t>(value >> 31);
  for (int b = 0; b < 4; ++b) file[a.offset + b * n + i] = static_cast<std::uint8_t>(z >> (8 * b));
  return file;
}

std::string reason_of(const std::vector<std::uint8_t>& file) {
  try {
    from_bytes(file.data(), file.size());
  } catch (const FormatError& e) {
    return e.reason();
  }
  return "accepted";
}

TEST(QuantizedComponents, CodesOutOfRangeAreRefusedByName) {
  WriteOptions w;
  w.component_precision = 0.5;
  w.compress = false;
  const std::vector<std::uint8_t> file = to_bytes(test::synthetic_model(6, 5), w);
  ASSERT_EQ(reason_of(file), "accepted");
  struct Case {
    int which;
    std::uint64_t column;
    std::int32_t value;
  };
  const Case cases[] = {{0, 0, 8},          // weight of exponent 1 > 0
                        {0, 0, -8 * 127},   // weight exponent -127
                        {2, 0, 17},         // f
                        {2, 0, -1},         // f
                        {2, 1, 1 << 30},    // eigenvalue exponent far above 127
                        {2, 5, 25},         // r
                        {2, 6, -1},         // u
                        {2, 7, 1 << 30},    // tilt above 1 (r <= 24)
                        {2, 9, 1 << 25},    // turn above 2^u
                        {2, 10, 41},        // s
                        {1, 0, 41},         // e
                        {1, 0, -2147483647 - 1}};
  for (const Case& c : cases) {
    EXPECT_EQ(reason_of(with_code(file, c.which, 3, c.column, c.value)), "bad_quantization")
        << "array " << c.which << " column " << c.column << " value " << c.value;
  }
  // A code in range but not the writer's: the CRC-32C of the decoded values says so.
  EXPECT_EQ(reason_of(with_code(file, 1, 2, 1, 12345)), "checksum_mismatch");
}

TEST(QuantizedComponents, HostileBytesNeverCrashOrGiveANonSpdModel) {
  WriteOptions w;
  w.component_precision = 0.25;
  w.compress = false;
  const std::vector<std::uint8_t> file = to_bytes(test::synthetic_model(8, 9), w);
  const FileInfo info = read_info(file.data(), file.size());
  const std::uint64_t body = info.weights.offset, end = file.size() - 4;
  std::mt19937 rng(11);
  ReadOptions no_crc;
  no_crc.verify_checksums = false;  // so that changed codes reach the decoder and step 19
  int accepted = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    std::vector<std::uint8_t> f = file;
    for (int e = 0; e < 1 + trial % 3; ++e) f[body + rng() % (end - body)] ^= static_cast<std::uint8_t>(1 + rng() % 255);
    try {
      const Model m = from_bytes(f.data(), f.size(), no_crc);
      ++accepted;
      for (std::size_t k = 0; k < m.gmm.size(); ++k) {
        double s[16];
        for (int i = 0; i < 16; ++i) s[i] = m.gmm.covariance(k)[i];
        ASSERT_TRUE(stored_cholesky(s));
        for (int i = 0; i < 4; ++i) ASSERT_TRUE(std::isfinite(m.gmm.mean(k)[i]));
        ASSERT_TRUE(std::isfinite(m.gmm.weights[k]));
      }
    } catch (const FormatError& e) {
      const std::string r = e.reason();
      EXPECT_TRUE(r == "bad_quantization" || r == "non_finite" || r == "not_spd" || r == "bad_weights") << r;
    }
  }
  EXPECT_GT(accepted, 0);
}

TEST(QuantizedComponents, FilterAndFeatureBitMustAgree) {
  // A quantized file whose weights claim another filter.
  WriteOptions w;
  w.component_precision = 0.5;
  std::vector<std::uint8_t> file = to_bytes(test::synthetic_model(4, 1), w);
  auto* root = fb::GetMutableSogmmFile(file.data() + 32);
  ASSERT_TRUE(root->mutable_weights()->mutate_filter(fb::Filter::BYTE_STREAM_SPLIT));
  detail::refresh_metadata_crc(file);
  EXPECT_EQ(reason_of(file), "unsupported_encoding");
  // A quantized file whose features lose bit 2 (the field is present: 4 != default).
  file = to_bytes(test::synthetic_model(4, 1), w);
  root = fb::GetMutableSogmmFile(file.data() + 32);
  ASSERT_TRUE(root->mutate_features_required(0));
  detail::refresh_metadata_crc(file);
  EXPECT_EQ(reason_of(file), "unsupported_encoding");
}

}  // namespace
}  // namespace sogmm::format
