// Helpers shared by the core tests: fixtures, independent model checks, error checks.
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <cstdint>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "sogmm/error.hpp"
#include "sogmm/gmm.hpp"

namespace sogmm_test {

inline nlohmann::json load_fixture(const std::string& name) {
  const std::string path = std::string(SOGMM_TEST_REFERENCE_DIR) + "/" + name;
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open fixture " + path +
                                    " (regenerate with tests/reference/make_core_fixtures.py)");
  return nlohmann::json::parse(in);
}

inline std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

/// Runs `f`, expects sogmm::Error with `code` whose message contains (case-
/// insensitively) at least one of `keywords`. Any other exception, or none, fails.
inline void expect_error_codes(const std::function<void()>& f, std::initializer_list<sogmm::ErrorCode> codes,
                               std::initializer_list<const char*> keywords, const char* what) {
  SCOPED_TRACE(what);
  try {
    f();
    ADD_FAILURE() << what << ": no exception thrown";
  } catch (const sogmm::Error& e) {
    bool code_ok = false;
    std::string expected;
    for (auto c : codes) {
      code_ok = code_ok || c == e.code();
      expected += " " + std::to_string(static_cast<int>(c));
    }
    EXPECT_TRUE(code_ok) << what << ": ErrorCode " << static_cast<int>(e.code()) << ", expected one of"
                         << expected << "; message: " << e.what();
    const std::string msg = lower(e.what());
    EXPECT_FALSE(msg.empty()) << what << ": empty message";
    bool found = false;
    std::string list;
    for (const char* k : keywords) {
      found = found || msg.find(lower(k)) != std::string::npos;
      list += std::string(" '") + k + "'";
    }
    EXPECT_TRUE(found) << what << ": message \"" << e.what() << "\" names none of" << list;
  } catch (const std::exception& e) {
    ADD_FAILURE() << what << ": threw a non-sogmm exception: " << e.what();
  }
}

inline void expect_error(const std::function<void()>& f, sogmm::ErrorCode code,
                         std::initializer_list<const char*> keywords, const char* what) {
  expect_error_codes(f, {code}, keywords, what);
}

/// Independent validity check (Eigen, double): M >= 1, sizes agree, finite,
/// weights >= 0 summing to 1, covariances symmetric positive definite.
inline ::testing::AssertionResult model_is_valid(const sogmm::Gmm& g, double wtol = 1e-4) {
  const std::size_t m = g.weights.size();
  if (m < 1) return ::testing::AssertionFailure() << "no components";
  if (g.means.size() != 4 * m || g.covariances.size() != 16 * m)
    return ::testing::AssertionFailure() << "array sizes disagree with M = " << m;
  double sum = 0.0;
  for (std::size_t k = 0; k < m; ++k) {
    if (!std::isfinite(g.weights[k]) || g.weights[k] < 0.0f)
      return ::testing::AssertionFailure() << "weight " << k << " = " << g.weights[k];
    sum += g.weights[k];
    for (int i = 0; i < 4; ++i)
      if (!std::isfinite(g.means[4 * k + i]))
        return ::testing::AssertionFailure() << "mean " << k << " not finite";
    Eigen::Matrix4d c;
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) {
        const float v = g.covariances[16 * k + 4 * i + j];
        if (!std::isfinite(v)) return ::testing::AssertionFailure() << "covariance " << k << " not finite";
        c(i, j) = v;
      }
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < i; ++j)
        if (std::fabs(c(i, j) - c(j, i)) > 1e-5 * std::max(std::fabs(c(i, j)), std::sqrt(c(i, i) * c(j, j))))
          return ::testing::AssertionFailure() << "covariance " << k << " not symmetric at (" << i << "," << j << ")";
    Eigen::LLT<Eigen::Matrix4d> llt(c);
    if (llt.info() != Eigen::Success || !(llt.matrixL().toDenseMatrix().diagonal().array() > 0).all())
      return ::testing::AssertionFailure() << "covariance " << k << " not positive definite";
  }
  if (std::fabs(sum - 1.0) > wtol) return ::testing::AssertionFailure() << "weights sum to " << sum;
  const std::string msg = sogmm::validation_error(g, wtol);
  if (!msg.empty()) return ::testing::AssertionFailure() << "sogmm::validation_error says: " << msg;
  return ::testing::AssertionSuccess();
}

inline Eigen::Vector4d mean_of(const sogmm::Gmm& g, std::size_t k) {
  return Eigen::Vector4d(g.means[4 * k], g.means[4 * k + 1], g.means[4 * k + 2], g.means[4 * k + 3]);
}
inline Eigen::Matrix4d cov_of(const sogmm::Gmm& g, std::size_t k) {
  Eigen::Matrix4d c;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) c(i, j) = g.covariances[16 * k + 4 * i + j];
  return c;
}
inline void set_component(sogmm::Gmm& g, std::size_t k, double w, const Eigen::Vector4d& mu,
                          const Eigen::Matrix4d& cov) {
  g.weights[k] = static_cast<float>(w);
  for (int i = 0; i < 4; ++i) g.means[4 * k + i] = static_cast<float>(mu(i));
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) g.covariances[16 * k + 4 * i + j] = static_cast<float>(cov(i, j));
}

/// Mean log-likelihood per point of a (float32) model on points, in double
/// (an independent check of the EM's own figure).
inline double score(const sogmm::Gmm& g, const std::vector<float>& pts) {
  const std::size_t n = pts.size() / 4, m = g.size();
  std::vector<Eigen::Matrix4d> l(m);
  std::vector<double> c(m);
  for (std::size_t k = 0; k < m; ++k) {
    l[k] = Eigen::LLT<Eigen::Matrix4d>(cov_of(g, k)).matrixL();
    c[k] = std::log(static_cast<double>(g.weights[k])) - l[k].diagonal().array().log().sum() - 2.0 * 1.8378770664093454836 /* log 2 pi */;
  }
  double total = 0.0;
  std::vector<double> lp(m);
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector4d x(pts[4 * i], pts[4 * i + 1], pts[4 * i + 2], pts[4 * i + 3]);
    double best = -INFINITY;
    for (std::size_t k = 0; k < m; ++k) {
      const Eigen::Vector4d y = l[k].triangularView<Eigen::Lower>().solve(x - mean_of(g, k));
      lp[k] = c[k] - 0.5 * y.squaredNorm();
      best = std::max(best, lp[k]);
    }
    double s = 0.0;
    for (std::size_t k = 0; k < m; ++k) s += std::exp(lp[k] - best);
    total += best + std::log(s);
  }
  return total / static_cast<double>(n);
}

/// Small deterministic normal generator independent of sogmm::Rng (splitmix64
/// + Box-Muller), for building synthetic data the core did not produce.
class TestRng {
 public:
  explicit TestRng(std::uint64_t s) : x_(s) {}
  std::uint64_t next() {
    std::uint64_t z = (x_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double uniform() { return static_cast<double>((next() >> 11) + 1) * 0x1.0p-53; }  // (0, 1]
  double normal() {
    if (have_) { have_ = false; return spare_; }
    const double r = std::sqrt(-2.0 * std::log(uniform())), t = 6.283185307179586 * uniform();
    spare_ = r * std::sin(t);
    have_ = true;
    return r * std::cos(t);
  }

 private:
  std::uint64_t x_;
  bool have_ = false;
  double spare_ = 0.0;
};

/// N points (rows of 4 floats) drawn from a known mixture, component by
/// component in blocks, then interleaved by a fixed shuffle. `labels` gets the
/// true component of each point.
inline std::vector<float> draw_mixture(const std::vector<Eigen::Vector4d>& mus,
                                       const std::vector<Eigen::Matrix4d>& covs,
                                       const std::vector<int>& counts, std::uint64_t seed,
                                       std::vector<int>* labels = nullptr) {
  TestRng rng(seed);
  std::vector<std::pair<int, Eigen::Vector4d>> rows;
  for (std::size_t k = 0; k < mus.size(); ++k) {
    const Eigen::Matrix4d l = covs[k].llt().matrixL();
    for (int n = 0; n < counts[k]; ++n) {
      Eigen::Vector4d z(rng.normal(), rng.normal(), rng.normal(), rng.normal());
      rows.emplace_back(static_cast<int>(k), mus[k] + l * z);
    }
  }
  for (std::size_t i = rows.size(); i > 1; --i) std::swap(rows[i - 1], rows[rng.next() % i]);
  std::vector<float> out;
  if (labels) labels->clear();
  for (auto& r : rows) {
    for (int i = 0; i < 4; ++i) out.push_back(static_cast<float>(r.second(i)));
    if (labels) labels->push_back(r.first);
  }
  return out;
}

// A room-like frame: 8 rotated planar patches (about 1 m, 3 mm thick) with
// gray gradients, 4000 points in the camera frame.
inline std::vector<float> frame_points() {
  TestRng r(2024);
  std::vector<float> pts;
  for (int patch = 0; patch < 8; ++patch) {
    Eigen::Matrix3d a;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) a(i, j) = r.normal();
    const Eigen::Matrix3d q = Eigen::HouseholderQR<Eigen::Matrix3d>(a).householderQ();
    const Eigen::Vector3d centre(r.uniform() * 2 - 1, r.uniform() - 0.5, 1.5 + 1.5 * r.uniform());
    const double g0 = r.uniform();
    for (int i = 0; i < 500; ++i) {
      const double u = r.uniform() - 0.5, v = 0.6 * (r.uniform() - 0.5);
      const Eigen::Vector3d p = centre + q * Eigen::Vector3d(u, v, 0.003 * r.normal());
      pts.insert(pts.end(), {static_cast<float>(p(0)), static_cast<float>(p(1)), static_cast<float>(p(2)),
                             static_cast<float>(g0 + 0.3 * u + 0.02 * r.normal())});
    }
  }
  return pts;
}

inline bool bit_identical(const sogmm::Gmm& a, const sogmm::Gmm& b) {
  auto same = [](const std::vector<float>& x, const std::vector<float>& y) {
    return x.size() == y.size() &&
           (x.empty() || std::memcmp(x.data(), y.data(), x.size() * sizeof(float)) == 0);
  };
  return same(a.weights, b.weights) && same(a.means, b.means) && same(a.covariances, b.covariances);
}

}  // namespace sogmm_test
