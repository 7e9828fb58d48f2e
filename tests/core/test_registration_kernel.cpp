// The registration's kernels (core/src/registration_kernel.hpp), the one
// SOGMM_ISA selects (ctest runs this file under sse2, avx2 and the default,
// here AVX-512), against independent truth:
// - terms: libm's exp of the same difference, within fast_exp_double's
//   documented 5e-16 relative (fast_exp.hpp: ln 2 split so that n ln2_hi is
//   exact, Taylor remainder below 2e-16, the Horner roundings, fused into
//   multiply-adds or not, below 2^-53 each and damped by |r| <= ln2 / 2 at
//   every step but the last two). Measured over 2 10^6 seeded x in
//   [-750, 0]: at most 4.7e-16 on SSE2 (no fused multiply-add), 3.2e-16 on
//   AVX2 and AVX-512; the test's 21,000 arguments are a subset of that
//   kind. Below -708 the kernel gives 0 (libm's is subnormal there).
// - pairs: the Gaussian's log-density written out with Eigen on the full
//   3 x 3 precision. The kernel's sums differ by roundings only (fused or
//   not): a relative 1e-12 of the sum of the terms' magnitudes bounds them
//   with a margin of 10^3 over a dozen roundings of 2^-53.
// Mutations tried: dropping fast_exp_double's 1/11! term (fails the first), the
// wrong precision entry in P r's second row (fails the second).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdint>
#include <vector>

#include "registration_kernel.hpp"
#include "test_util.hpp"

namespace {
using namespace sogmm_test;
using namespace sogmm::detail;

TEST(RegistrationKernel, TermsAreExpWithinItsBound) {
  TestRng rng(5);
  std::vector<double> lp, top;
  // Every 1e-3 of [-1, 0] (small arguments), then seeded ones over [-750, 0]
  // with tops of either sign.
  for (int i = 0; i <= 1000; ++i) {
    lp.push_back(-1e-3 * i);
    top.push_back(0.0);
  }
  for (int i = 0; i < 20000; ++i) {
    const double t = 200.0 * (rng.uniform() - 0.5);
    top.push_back(t);
    lp.push_back(t - 750.0 * rng.uniform());
  }
  std::vector<double> term(lp.size());
  registration_kernels().terms(lp.data(), top.data(), term.data(), lp.size());
  std::size_t normal = 0;
  for (std::size_t j = 0; j < lp.size(); ++j) {
    const double x = lp[j] - top[j];
    if (x < -708.0) {
      EXPECT_EQ(term[j], 0.0) << "x = " << x;
      continue;
    }
    const double want = std::exp(x);
    ASSERT_LE(std::abs(term[j] - want), 5e-16 * want) << "x = " << x;
    ++normal;
  }
  EXPECT_GT(normal, lp.size() * 9 / 10);
}

// m random pair records (records: m x kPairRecord) and their spatial
// precisions (sigmas of ~1 cm), drawn from rng.
void random_records(TestRng& rng, std::vector<double>& records, std::vector<Eigen::Matrix3d>& prec) {
  for (std::size_t k = 0; k < prec.size(); ++k) {
    double* r = records.data() + k * kPairRecord;
    Eigen::Matrix3d a;
    for (int i = 0; i < 9; ++i) a(i / 3, i % 3) = rng.normal();
    prec[k] = a * a.transpose() / 1e-4 + 100.0 * Eigen::Matrix3d::Identity();
    const int upper[6][2] = {{0, 0}, {0, 1}, {0, 2}, {1, 1}, {1, 2}, {2, 2}};
    for (int e = 0; e < 6; ++e) r[kP00 + e] = prec[k](upper[e][0], upper[e][1]);
    for (int d = 0; d < 3; ++d) {
      r[kMuX + d] = rng.uniform();
      r[kGainX + d] = 0.1 * rng.normal();
    }
    r[kMuGray] = rng.uniform();
    r[kInvSgg] = 1.0 / (0.01 + 0.1 * rng.uniform());
    r[kLogNorm] = 5.0 * rng.normal();
    r[kLogNormGray] = rng.normal();
  }
}

TEST(RegistrationKernel, PairsAreTheGaussiansLogDensity) {
  TestRng rng(9);
  const std::size_t m = 40, count = 3000;
  std::vector<double> records(m * kPairRecord);
  std::vector<Eigen::Matrix3d> prec(m);
  random_records(rng, records, prec);
  std::vector<std::uint32_t> id(count);
  std::vector<double> x(count), y(count), z(count), gray(count), lp(count), px(count), py(count), pz(count),
      quad(count);
  for (std::size_t j = 0; j < count; ++j) {
    id[j] = static_cast<std::uint32_t>(rng.uniform() * m) % m;
    const double* r = records.data() + id[j] * kPairRecord;
    x[j] = r[kMuX] + 0.03 * rng.normal();
    y[j] = r[kMuY] + 0.03 * rng.normal();
    z[j] = r[kMuZ] + 0.03 * rng.normal();
    gray[j] = rng.uniform();
  }
  registration_kernels().pairs(records.data(),
                               {id.data(), x.data(), y.data(), z.data(), gray.data(), nullptr, nullptr, nullptr,
                                lp.data(), px.data(), py.data(), pz.data(), quad.data(), nullptr, nullptr, nullptr,
                                nullptr},
                               count);
  for (std::size_t j = 0; j < count; ++j) {
    const double* r = records.data() + id[j] * kPairRecord;
    const double dg = gray[j] - r[kMuGray];
    const Eigen::Vector3d res = Eigen::Vector3d(x[j], y[j], z[j]) - Eigen::Vector3d(r[kMuX], r[kMuY], r[kMuZ]) -
                                dg * Eigen::Vector3d(r[kGainX], r[kGainY], r[kGainZ]);
    const Eigen::Vector3d pr = prec[id[j]] * res;
    const double q = res.dot(pr);
    const double gray_term = 0.5 * dg * dg * r[kInvSgg];
    const double want = r[kLogNorm] + r[kLogNormGray] - gray_term - 0.5 * q;
    // |r|^T |P| |r|: what the quadratic form's roundings scale with.
    const double q_scale = res.cwiseAbs().dot(prec[id[j]].cwiseAbs() * res.cwiseAbs());
    const double scale = std::abs(r[kLogNorm]) + std::abs(r[kLogNormGray]) + gray_term + 0.5 * q_scale;
    ASSERT_NEAR(lp[j], want, 1e-12 * scale) << "pair " << j;
    ASSERT_NEAR(quad[j], q, 1e-12 * q_scale) << "pair " << j;
    const double pr_scale = prec[id[j]].cwiseAbs().maxCoeff() * res.cwiseAbs().sum();
    EXPECT_NEAR(px[j], pr(0), 1e-12 * pr_scale);
    EXPECT_NEAR(py[j], pr(1), 1e-12 * pr_scale);
    EXPECT_NEAR(pz[j], pr(2), 1e-12 * pr_scale);
  }
}

// With a depth-noise axis u per pair: the log-density of N(x; mu + gain dg,
// P^-1 + u u^T) written out with Eigen (the covariance formed, factored and
// inverted: no rank-one formula), and that covariance's inverse against the
// kernel's P - shrink (P u)(P u)^T. u of 1 to 20 mm against sigmas of ~1 cm:
// the update changes the terms by up to a few units, the log det by up to
// log 5. The sums differ by roundings and by fast_log_ge1's 1e-15 relative:
// bounds of 1e-10 relative leave a margin of 10^4 over the inverse's
// conditioning (about 10^3 here). Mutation tried: 0.5 * log(grow) dropped
// (fails the log-density).
TEST(RegistrationKernel, PairsWithDepthNoiseAddTheRankOneCovariance) {
  TestRng rng(11);
  const std::size_t m = 30, count = 2000;
  std::vector<double> records(m * kPairRecord);
  std::vector<Eigen::Matrix3d> prec(m);
  random_records(rng, records, prec);
  std::vector<std::uint32_t> id(count);
  std::vector<double> x(count), y(count), z(count), gray(count), ux(count), uy(count), uz(count), lp(count),
      px(count), py(count), pz(count), quad(count), pux(count), puy(count), puz(count), shrink(count);
  for (std::size_t j = 0; j < count; ++j) {
    id[j] = static_cast<std::uint32_t>(rng.uniform() * m) % m;
    const double* r = records.data() + id[j] * kPairRecord;
    x[j] = r[kMuX] + 0.03 * rng.normal();
    y[j] = r[kMuY] + 0.03 * rng.normal();
    z[j] = r[kMuZ] + 0.03 * rng.normal();
    gray[j] = rng.uniform();
    Eigen::Vector3d u(rng.normal(), rng.normal(), rng.normal());
    u *= (0.001 + 0.019 * rng.uniform()) / u.norm();
    ux[j] = u(0);
    uy[j] = u(1);
    uz[j] = u(2);
  }
  registration_kernels().pairs(records.data(),
                               {id.data(), x.data(), y.data(), z.data(), gray.data(), ux.data(), uy.data(), uz.data(),
                                lp.data(), px.data(), py.data(), pz.data(), quad.data(), pux.data(), puy.data(),
                                puz.data(), shrink.data()},
                               count);
  for (std::size_t j = 0; j < count; ++j) {
    const double* r = records.data() + id[j] * kPairRecord;
    const Eigen::Vector3d u(ux[j], uy[j], uz[j]);
    const Eigen::Matrix3d cov0 = prec[id[j]].inverse();
    const Eigen::Matrix3d cov = cov0 + u * u.transpose();
    const Eigen::LLT<Eigen::Matrix3d> llt0(cov0), llt(cov);
    const double log_grow = 2.0 * (llt.matrixLLT().diagonal().array().log().sum() -
                                   llt0.matrixLLT().diagonal().array().log().sum());
    const Eigen::Matrix3d p_new = llt.solve(Eigen::Matrix3d::Identity());
    const double dg = gray[j] - r[kMuGray];
    const Eigen::Vector3d res = Eigen::Vector3d(x[j], y[j], z[j]) - Eigen::Vector3d(r[kMuX], r[kMuY], r[kMuZ]) -
                                dg * Eigen::Vector3d(r[kGainX], r[kGainY], r[kGainZ]);
    const Eigen::Vector3d pr = p_new * res;
    const double q = res.dot(pr);
    const double gray_term = 0.5 * dg * dg * r[kInvSgg];
    const double want = r[kLogNorm] + r[kLogNormGray] - gray_term - 0.5 * log_grow - 0.5 * q;
    const double q_scale = res.cwiseAbs().dot(prec[id[j]].cwiseAbs() * res.cwiseAbs());
    const double scale = std::abs(r[kLogNorm]) + std::abs(r[kLogNormGray]) + gray_term + log_grow + 0.5 * q_scale;
    ASSERT_NEAR(lp[j], want, 1e-10 * scale) << "pair " << j;
    ASSERT_NEAR(quad[j], q, 1e-10 * q_scale) << "pair " << j;
    const double pr_scale = prec[id[j]].cwiseAbs().maxCoeff() * res.cwiseAbs().sum();
    EXPECT_NEAR(px[j], pr(0), 1e-10 * pr_scale);
    EXPECT_NEAR(py[j], pr(1), 1e-10 * pr_scale);
    EXPECT_NEAR(pz[j], pr(2), 1e-10 * pr_scale);
    // The caller's precision P - shrink (P u)(P u)^T.
    const Eigen::Vector3d pu(pux[j], puy[j], puz[j]);
    const Eigen::Matrix3d p_kernel = prec[id[j]] - shrink[j] * pu * pu.transpose();
    ASSERT_LE((p_kernel - p_new).cwiseAbs().maxCoeff(), 1e-10 * prec[id[j]].cwiseAbs().maxCoeff()) << "pair " << j;
  }
}

}  // namespace
