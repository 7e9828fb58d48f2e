// EM properties (issue 14): exact at any offset and scale, thread-count and
// instruction-set independence, the truncated E-step within its bound, the
// multi-wave path, and large rotated geometry against scikit-learn.
#include <gtest/gtest.h>
#include <sys/types.h>
#include <unistd.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "em_regions.hpp"
#include "sogmm/em.hpp"
#include "sogmm/error.hpp"
#include "sogmm/fit.hpp"
#include "sogmm/kmeanspp.hpp"
#include "test_util.hpp"
#include "thread_fits.hpp"

namespace {

using sogmm_test::score;

using sogmm_test::frame_points;

sogmm::PointsView view(const std::vector<float>& p) { return {p.data(), p.size() / 4}; }

// The float32 points of one case of em_large_geometry.json.
std::vector<float> large_geometry_points(const std::string& name) {
  const nlohmann::json ref = sogmm_test::load_fixture("em_large_geometry.json");
  for (const auto& c : ref.at("cases"))
    if (c.at("name").get<std::string>() == name) {
      std::vector<float> pts;
      for (const auto& row : c.at("points"))
        for (const auto& v : row) pts.push_back(static_cast<float>(v.get<double>()));
      return pts;
    }
  ADD_FAILURE() << "no case " << name << " in em_large_geometry.json";
  return {};
}

}  // namespace

// A fixed-K fit of a float32 cloud moved by 10 m, 1 km and 10 km gives the
// same mean log-likelihood as the same float32 cloud at the origin, within
// 1e-3 nats/point plus what float32 storage of the final means costs there.
TEST(EmProperties, TranslationKeepsTheLikelihood) {
  const std::vector<float> base = frame_points();
  const Eigen::Vector3d dir = Eigen::Vector3d(1.0, -0.6, 0.8).normalized();
  for (double t : {10.0, 1e3, 1e4}) {
    SCOPED_TRACE("offset " + std::to_string(t) + " m");
    float off[3];
    for (int j = 0; j < 3; ++j) off[j] = static_cast<float>(t * dir(j));
    std::vector<float> far = base, near = base;
    for (std::size_t i = 0; i < base.size() / 4; ++i)
      for (int j = 0; j < 3; ++j) {
        far[4 * i + j] = base[4 * i + j] + off[j];
        // Exact: the far cloud moved back, the same float32 cloud at the origin.
        near[4 * i + j] = static_cast<float>(static_cast<double>(far[4 * i + j]) - off[j]);
        ASSERT_EQ(static_cast<double>(near[4 * i + j]), static_cast<double>(far[4 * i + j]) - off[j]);
      }
    sogmm::FitOptions o;
    o.n_components = 16;
    o.seed = 3;
    const sogmm::FitResult a = sogmm::fit(view(far), o), b = sogmm::fit(view(near), o);
    ASSERT_TRUE(sogmm_test::model_is_valid(a.gmm));
    ASSERT_TRUE(sogmm_test::model_is_valid(b.gmm));
    const double s_far = score(a.gmm, far), s_near = score(b.gmm, near);
    // The near model with its means stored at the offset, moved back.
    sogmm::Gmm stored = b.gmm;
    for (std::size_t k = 0; k < stored.size(); ++k)
      for (int j = 0; j < 3; ++j)
        stored.means[4 * k + j] =
            static_cast<float>(static_cast<double>(static_cast<float>(b.gmm.means[4 * k + j] + static_cast<double>(off[j]))) - off[j]);
    const double storage = std::fabs(s_near - score(stored, near));
    EXPECT_NEAR(s_far, s_near, 1e-3 + storage) << "storage cost " << storage;
    EXPECT_NEAR(a.em.log_likelihood, b.em.log_likelihood, 1e-3);
  }
}

namespace {

// Fits one case of em_large_geometry.json with `reg_covar` (unset: auto) as
// sklearn's reference did (8 inits, max_iter 1000: compare optima, not
// iteration limits); the fit must succeed, be positive definite in float32 and
// score no worse than 0.1 nats/point below `sklearn`.
sogmm::FitResult expect_close_to_sklearn(const nlohmann::json& c, std::optional<double> reg_covar, double sklearn) {
  const std::string name = c.at("name").get<std::string>();
  std::vector<float> pts;
  for (const auto& row : c.at("points"))
    for (const auto& v : row) pts.push_back(static_cast<float>(v.get<double>()));
  sogmm::FitOptions o;
  o.n_components = c.at("n_components").get<std::size_t>();
  o.em.reg_covar = reg_covar;
  o.n_init = 8;
  o.em.max_iter = 1000;
  sogmm::FitResult r;
  EXPECT_NO_THROW(r = sogmm::fit(view(pts), o));
  if (r.gmm.size() == 0) return r;
  EXPECT_TRUE(sogmm_test::model_is_valid(r.gmm));
  const double s = score(r.gmm, pts);
  EXPECT_GE(s, sklearn - 0.1) << "sogmm " << s << " vs sklearn " << sklearn;
  std::printf("%s (reg_covar %s): sogmm %.5f, report %.5f, sklearn %.5f\n", name.c_str(),
              reg_covar ? std::to_string(*reg_covar).c_str() : "auto", s, r.em.log_likelihood, sklearn);
  return r;
}

}  // namespace

// Large rotated geometry (fixture from tests/reference/make_em_scale_fixture.py):
// each fit succeeds, is positive definite in float32, and scores no worse
// than 0.1 nats/point below scikit-learn's best of 8 inits. (The 1 km plane
// with 1 cm noise landed 0.21 below while the kernels evaluated its
// components in float32: see LikelihoodNeverDecreasesAtKilometreScale.)
TEST(EmProperties, LargeRotatedGeometryMatchesSklearn) {
  const nlohmann::json ref = sogmm_test::load_fixture("em_large_geometry.json");
  for (const auto& c : ref.at("cases")) {
    SCOPED_TRACE(c.at("name").get<std::string>());
    expect_close_to_sklearn(c, c.at("reg_covar").get<double>(), c.at("sklearn_score").get<double>());
  }
}

// The same with the default, automatic reg_covar (issue 14): a 1 km plane
// gets a spatial floor of 1 m^2 and gray keeps 1e-6, which float32 can hold;
// the fixture's floors come from an independent implementation of the rule
// and its reference from sklearn fitted with the same floors.
TEST(EmProperties, LargeRotatedGeometryWithAutomaticRegCovarMatchesSklearn) {
  const nlohmann::json ref = sogmm_test::load_fixture("em_large_geometry.json");
  for (const auto& c : ref.at("cases")) {
    SCOPED_TRACE(c.at("name").get<std::string>());
    const nlohmann::json& a = c.at("auto");
    const sogmm::FitResult r = expect_close_to_sklearn(c, std::nullopt, a.at("sklearn_score").get<double>());
    EXPECT_TRUE(r.em.reg_covar.automatic);
    EXPECT_EQ(r.em.reg_covar.spatial, a.at("reg_covar_spatial").get<double>());
    EXPECT_EQ(r.em.reg_covar.gray, a.at("reg_covar_gray").get<double>());
  }
}

// EM never lowers the log-likelihood (each E+M step is a coordinate ascent),
// so the E-step's value may fall only by the kernels' rounding. On the 1 km
// plane with 1 cm noise the float32 kernels lost the plane's thickness: the
// whitened coordinate U^T (x - mu) cancels ~4.5 of float's 7 digits, and the
// float32 second moments (entries ~1e4 m^2) carry errors far above the
// 1e-4 m^2 thickness, so the value jumped by up to 0.6 nats between
// iterations and stopped on chance (0.21 nats below scikit-learn). Components
// that elongated are now evaluated in double (em.cpp, needs_double).
TEST(EmProperties, LikelihoodNeverDecreasesAtKilometreScale) {
  for (const std::string name : {"plane_30m_1cm", "line_100m_1cm", "plane_1km_1cm", "plane_1km_5cm"}) {
    SCOPED_TRACE(name);
    const std::vector<float> pts = large_geometry_points(name);
    for (std::uint64_t seed : {0, 1, 2}) {
      sogmm::EmOptions o;
      // Components thin enough for the double kernels. (With the automatic
      // floors, 1e-4 m^2 at 30-100 m and 1 m^2 at 1 km, the components stay
      // in float32, whose rounding moves the value by up to ~1e-4 nats.)
      o.reg_covar = 1e-6;
      o.max_iter = 40;
      o.tol = 0.0;
      std::vector<double> ll;
      sogmm::fit_em(view(pts), sogmm::kmeanspp_seeds(view(pts), 10, seed), o, nullptr,
                    [&](int, double v) { ll.push_back(v); });
      for (std::size_t i = 2; i < ll.size(); ++i)  // from the 2nd: the 1st scores the k-means++ start
        EXPECT_GE(ll[i], ll[i - 1] - 1e-5) << "seed " << seed << ", iteration " << i + 1;
    }
  }
}

// Results are bitwise identical for 1, 2 and 3 threads (3 does not divide the
// 16 chunks of a wave).
TEST(EmProperties, BitIdenticalForOneTwoThreeThreads) {
  const std::vector<float> pts = frame_points();
  sogmm::FitOptions o;
  o.n_components = 20;
  o.seed = 9;
  sogmm_test::expect_same_fit_for_one_two_three_threads(pts, o, "frame");
  // The same for components the kernels evaluate in double (a 1 km plane).
  o.n_components = 10;
  o.em.reg_covar = 1e-6;  // thin components: the double kernels (auto gives 1 m^2, float32 kernels)
  sogmm_test::expect_same_fit_for_one_two_three_threads(large_geometry_points("plane_1km_1cm"), o, "1 km plane");
}

// 4-D scaling: x, y, z, gray by s, bandwidth by s, reg_covar by s^2 gives the
// same M and iterations and the log-likelihood shifted by -4 ln s. The test
// keeps float32 rounding of the inputs out: the frame is put on a grid of
// 10 x 2^-16 (0.15 mm, 0.00015 in gray), on which s = 2^j k / 10 for integer
// k gives exactly representable float32 points n k 2^(j-16). (Rounding the
// scaled inputs to float32 instead moves the likelihood of one and the same
// model by up to 4.7e-7 at s = 7 and 2.7e-7 at s = 0.1 on this scene: the
// data changing, not the fit.)
// - s a power of two: every float32 operation of the fit scales exactly, and
//   the E-step's constants are shifted by their largest (em.cpp, pack_all),
//   so the fit is the same and the log-likelihood moves by -4 ln s to double
//   rounding: bound 1e-12.
// - other s: the float32 E-step (unit roundoff u = 6e-8) rounds the centred
//   points and the whitened coordinates differently at each scale, and the
//   iterations carry that into the final log-likelihood. Bound 5e-6 (the
//   issue's decision; a double E-step would remove it at 2x the EM cost).
// The bound is a rounding bound, so it must hold for every kernel, and ctest
// runs this suite under SOGMM_ISA=sse2, avx2 and the default
// (tests/core/CMakeLists.txt). Why it also holds for AVX-512, which the CI
// machine lacks: the kernels evaluate the same per-term float32 expressions
// (em_kernel.cpp is one source compiled three times); AVX2 and AVX-512 both
// fuse multiply-adds (fewer roundings than SSE2), and they differ only in the
// lane width over which a block's statistics are summed, whose error bound
// (n / w + log2 w) u sum|terms| shrinks as the width w grows. Measured worst
// on this scene: SSE2 5.6e-7, AVX2 6.7e-7, AVX-512 1.54e-6 (AMD EPYC, at
// s = 0.3): the bound leaves 3x over the largest of them.
TEST(EmProperties, FourDimensionalScaleInvariance) {
  const std::vector<float> pts = frame_points();
  std::vector<double> grid(pts.size());  // integer multiples n of 10 x 2^-16
  for (std::size_t i = 0; i < pts.size(); ++i) grid[i] = std::nearbyint(pts[i] / (10 * 0x1p-16));
  auto scaled = [&](int k, int j) {  // the grid cloud scaled by s = 2^j k / 10, exactly
    std::vector<float> out(pts.size());
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const double v = std::ldexp(grid[i] * k, j - 16);
      out[i] = static_cast<float>(v);
      EXPECT_EQ(static_cast<double>(out[i]), v) << "not exact at k = " << k << ", j = " << j;
    }
    return out;
  };
  sogmm::FitOptions o;
  o.bandwidth = 0.05;
  o.seed = 4;
  o.em.reg_covar = 1e-6;  // explicit, so that it can scale with s^2
  const sogmm::FitResult a = sogmm::fit(view(scaled(10, 0)), o);
  double worst = 0.0, worst_pow2 = 0.0;
  struct Scale {
    int k, j;
  };
  for (Scale c : {Scale{10, 1}, Scale{10, -1}, Scale{10, 3}, Scale{10, -4}, Scale{10, 10}, Scale{100, 0},
                  Scale{1, 0}, Scale{30, 0}, Scale{70, 0}, Scale{3, 0}}) {
    const double s = std::ldexp(c.k / 10.0, c.j);
    const bool pow2 = c.k == 10;
    SCOPED_TRACE("s = " + std::to_string(s));
    sogmm::FitOptions os = o;
    os.bandwidth = o.bandwidth * s;
    os.em.reg_covar = *o.em.reg_covar * s * s;
    const sogmm::FitResult b = sogmm::fit(view(scaled(c.k, c.j)), os);
    EXPECT_EQ(a.gmm.size(), b.gmm.size());
    EXPECT_EQ(a.em.iterations, b.em.iterations);
    const double deviation = b.em.log_likelihood - (a.em.log_likelihood - 4.0 * std::log(s));
    EXPECT_NEAR(deviation, 0.0, pow2 ? 1e-12 : 5e-6) << "kernel " << b.em.kernel;
    (pow2 ? worst_pow2 : worst) = std::max(pow2 ? worst_pow2 : worst, std::fabs(deviation));
    std::printf("s = %g: M %zu, log-likelihood deviation %.2e\n", s, b.gmm.size(), deviation);
  }
  std::printf("kernel %s: largest deviation %.2e at powers of two (bound 1e-12), %.2e elsewhere (bound 5e-6)\n",
              a.em.kernel, worst_pow2, worst);
}

// The truncated E-step (truncation_nats = 25) stays within its documented
// bound of the exact one: every skipped term weighs < exp(-25) of its point's
// largest, so the log-likelihood of an E-step from the same model differs by
// at most log(1 + M exp(-25)); later iterations drift apart only by float
// noise (1e-5 nats/point).
TEST(EmProperties, TruncatedEStepWithinItsBound) {
  const std::vector<float> pts = frame_points();
  const std::vector<std::size_t> seeds = sogmm::kmeanspp_seeds(view(pts), 24, 5);
  std::vector<double> exact, truncated;
  sogmm::EmOptions o;
  o.max_iter = 12;
  o.tol = 0.0;
  sogmm::fit_em(view(pts), seeds, o, nullptr, [&](int, double ll) { exact.push_back(ll); });
  o.truncation_nats = 25.0;
  sogmm::EmReport rep;
  sogmm::fit_em(view(pts), seeds, o, &rep, [&](int, double ll) { truncated.push_back(ll); });
  ASSERT_EQ(exact.size(), truncated.size());
  EXPECT_LT(rep.pair_fraction, 0.9) << "nothing was skipped: the test would be vacuous";
  const double bound = std::log1p(24 * std::exp(-25.0));
  EXPECT_NEAR(truncated[0], exact[0], bound + 1e-9) << "first E-step (same model)";
  for (std::size_t i = 1; i < exact.size(); ++i) EXPECT_NEAR(truncated[i], exact[i], 1e-5) << "iteration " << i + 1;
}

// The truncated E-step keeps state across iterations (per-block warm lists,
// per-group candidates from the previous cuts); none of it may depend on
// which thread ran a block: 1, 2 and 3 threads give the same bits, on a
// cloud of 16 blocks (two bound groups) with a third of the pairs skipped.
TEST(EmProperties, TruncatedBitIdenticalForOneTwoThreeThreads) {
  const std::vector<float> pts = frame_points();
  const std::vector<std::size_t> seeds = sogmm::kmeanspp_seeds(view(pts), 24, 6);
  sogmm::EmOptions o;
  o.max_iter = 15;
  o.tol = 0.0;
  o.truncation_nats = 8.0;
  std::vector<sogmm::Gmm> g;
  std::vector<sogmm::EmReport> rep(3);
  for (int threads : {1, 2, 3}) {
    o.threads = threads;
    g.push_back(sogmm::fit_em(view(pts), seeds, o, &rep[static_cast<std::size_t>(threads - 1)]));
  }
  EXPECT_LT(rep[0].pair_fraction, 0.8) << "too little skipped: the test would be vacuous";
  for (int i : {1, 2}) {
    EXPECT_TRUE(sogmm_test::bit_identical(g[0], g[i])) << "1 vs " << i + 1 << " threads";
    EXPECT_EQ(rep[0].log_likelihood, rep[i].log_likelihood);
    EXPECT_EQ(rep[0].pair_fraction, rep[i].pair_fraction);
  }
}

// The M-step, the Cholesky packing and SQUAREM's step length and load check
// run on the team in claims of kComponentsPerClaim (64) components: with 150
// components a claim boundary falls inside the model for 2 and 3 threads, and
// the bits must still not depend on the team (each component's work is its
// own; sums are formed in component order).
TEST(EmProperties, ComponentClaimsBitIdenticalForOneTwoThreeThreads) {
  const std::vector<float> pts = frame_points();
  const std::vector<std::size_t> seeds = sogmm::kmeanspp_seeds(view(pts), 150, 4);
  for (sogmm::EmAcceleration acc : {sogmm::EmAcceleration::None, sogmm::EmAcceleration::Squarem}) {
    sogmm::EmOptions o;
    o.max_iter = 8;
    o.tol = 0.0;
    o.reg_covar = 1e-6;
    o.acceleration = acc;
    std::vector<sogmm::Gmm> g;
    std::vector<sogmm::EmReport> rep(3);
    for (int threads : {1, 2, 3}) {
      o.threads = threads;
      g.push_back(sogmm::fit_em(view(pts), seeds, o, &rep[static_cast<std::size_t>(threads - 1)]));
    }
    ASSERT_EQ(g[0].size(), 150u);
    for (int i : {1, 2}) {
      EXPECT_TRUE(sogmm_test::bit_identical(g[0], g[i])) << "1 vs " << i + 1 << " threads, acceleration " << int(acc);
      EXPECT_EQ(rep[0].log_likelihood, rep[i].log_likelihood);
      EXPECT_EQ(rep[0].iterations, rep[i].iterations);
    }
  }
}

// More than one wave of chunks (N > 16 x 32 x 256 points): a cloud repeated
// 40 times has the same EM iterates as the cloud itself (responsibilities
// equal, sums x40), and threads still do not change a bit.
TEST(EmProperties, MultiWavePathMatchesTheSingleCopy) {
  const std::vector<float> pts = frame_points();
  std::vector<float> many;
  for (int c = 0; c < 40; ++c) many.insert(many.end(), pts.begin(), pts.end());
  ASSERT_GT(many.size() / 4, 16u * 32u * 256u);
  const std::vector<std::size_t> seeds = sogmm::kmeanspp_seeds(view(pts), 6, 2);
  sogmm::EmOptions o;
  o.max_iter = 4;
  o.tol = 0.0;
  o.threads = 1;
  sogmm::EmReport r1, r40, r40b;
  const sogmm::Gmm one = sogmm::fit_em(view(pts), seeds, o, &r1);
  const sogmm::Gmm forty = sogmm::fit_em(view(many), seeds, o, &r40);
  o.threads = 2;
  const sogmm::Gmm forty2 = sogmm::fit_em(view(many), seeds, o, &r40b);
  EXPECT_TRUE(sogmm_test::bit_identical(forty, forty2));
  EXPECT_NEAR(r40.log_likelihood, r1.log_likelihood, 1e-6);
  for (std::size_t k = 0; k < one.size(); ++k) {
    EXPECT_NEAR(forty.weights[k], one.weights[k], 1e-6);
    EXPECT_LT((sogmm_test::mean_of(forty, k) - sogmm_test::mean_of(one, k)).cwiseAbs().maxCoeff(), 1e-6);
    const Eigen::Matrix4d c = sogmm_test::cov_of(one, k);
    EXPECT_LT((sogmm_test::cov_of(forty, k) - c).cwiseAbs().maxCoeff(), 1e-5 * c.cwiseAbs().maxCoeff());
  }
}

// The E-step's chunks run in parallel regions of as many chunks as 16 MiB of
// their statistics allow (em_regions.hpp); real fits start a second region
// only at M of a few thousand beyond 131k points. With the budget at one byte
// every region holds one wave of 16 chunks, so the 40-copy cloud (more than
// 16 x 32 blocks, hence more than 16 chunks) takes several regions per pass:
// exact and truncated, 1 and 2 threads, the bits are those of one region.
TEST(EmProperties, RegionsPerPassDoNotChangeABit) {
  const std::vector<float> pts = frame_points();
  std::vector<float> many;
  for (int c = 0; c < 40; ++c) many.insert(many.end(), pts.begin(), pts.end());
  ASSERT_GT(many.size() / 4, 16u * 32u * 256u) << "one region would hold every chunk: the test would be vacuous";
  const std::vector<std::size_t> seeds = sogmm::kmeanspp_seeds(view(pts), 24, 3);
  for (double nats : {0.0, 8.0}) {
    sogmm::EmOptions o;
    o.max_iter = 4;
    o.tol = 0.0;
    o.truncation_nats = nats;
    sogmm::EmReport one_region;
    const sogmm::Gmm reference = sogmm::fit_em(view(many), seeds, o, &one_region);
    const std::size_t previous = sogmm::detail::set_em_region_bytes(1);
    for (int threads : {1, 2}) {
      SCOPED_TRACE("truncation " + std::to_string(nats) + ", threads " + std::to_string(threads));
      o.threads = threads;
      sogmm::EmReport regions;
      const sogmm::Gmm g = sogmm::fit_em(view(many), seeds, o, &regions);
      EXPECT_TRUE(sogmm_test::bit_identical(reference, g));
      EXPECT_EQ(one_region.log_likelihood, regions.log_likelihood);
      EXPECT_EQ(one_region.pair_fraction, regions.pair_fraction);
    }
    sogmm::detail::set_em_region_bytes(previous);
    if (nats > 0) {
      EXPECT_LT(one_region.pair_fraction, 0.9) << "nothing was skipped: the truncated case would be vacuous";
    }
  }
}

// Every EM kernel the CPU supports gives the same result within
// max(2.4e-6, 1e-9 |LL|) nats on the same input. SOGMM_ISA caps the kernel choice, which is made once
// per process, so each kernel runs in a fresh child process (gtest's
// "threadsafe" death-test style re-executes the test binary) and reports its
// log-likelihood through a file; on a CPU without AVX2 or AVX-512 the cap
// simply selects the best kernel it has.
// Where the child for `isa` of test process `pid` writes its result: named
// by the process, since ctest runs this test and its isa_* copies at once
// (and other checkouts may too), and a shared name let one run remove
// another's file before it was read.
namespace {
std::string kernel_result_file(const std::string& isa, pid_t pid) {
  return ::testing::TempDir() + "sogmm_em_kernel_" + isa + "_" + std::to_string(pid) + ".txt";
}
}  // namespace

TEST(EmProperties, EveryKernelAgrees) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  std::vector<double> ll, plane_ll;
  for (const std::string isa : {"sse2", "avx2", "best"}) {
    EXPECT_EXIT(
        {
          if (isa == "best") ::unsetenv("SOGMM_ISA");
          else ::setenv("SOGMM_ISA", isa.c_str(), 1);
          const std::vector<float> pts = frame_points();
          sogmm::EmOptions o;
          o.max_iter = 10;
          o.tol = 0.0;
          sogmm::EmReport rep;
          sogmm::EmReport plane_rep;
          sogmm::fit_em(view(pts), sogmm::kmeanspp_seeds(view(pts), 20, 8), o, &rep);
          // and components the kernels evaluate in double (a 1 km plane)
          const std::vector<float> plane = large_geometry_points("plane_1km_1cm");
          o.reg_covar = 1e-6;  // thin components: the double kernels (auto gives 1 m^2 and float32 kernels)
          sogmm::fit_em(view(plane), sogmm::kmeanspp_seeds(view(plane), 10, 1), o, &plane_rep);
          // The child's parent is the test process that reads the file.
          const std::string file = kernel_result_file(isa, ::getppid());
          std::FILE* f = std::fopen(file.c_str(), "w");
          const bool ok = f != nullptr &&
                          std::fprintf(f, "%a %s %a\n", rep.log_likelihood, rep.kernel, plane_rep.log_likelihood) > 0 &&
                          std::fclose(f) == 0;
          std::exit(ok ? 0 : 1);
        },
        ::testing::ExitedWithCode(0), "");
  }
  // Read only after every child has run: a child re-executes this body up
  // to its own death test, so nothing it would see may be removed before.
  // The kernel each child should have run, from the CPU's own flags.
  const bool has_avx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  const bool has_avx512 = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
                          __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512bw");
  const std::map<std::string, std::string> expected{
      {"sse2", "sse2"}, {"avx2", has_avx2 ? "avx2" : "sse2"},
      {"best", has_avx512 ? "avx512" : (has_avx2 ? "avx2" : "sse2")}};
  for (const std::string isa : {"sse2", "avx2", "best"}) {
    const std::string file = kernel_result_file(isa, ::getpid());
    std::ifstream in(file);
    std::string text, ran, plane_text;
    ASSERT_TRUE(static_cast<bool>(in >> text >> ran >> plane_text)) << isa << ": no result in " << file;
    EXPECT_EQ(ran, expected.at(isa)) << "SOGMM_ISA=" << isa;
    ll.push_back(std::strtod(text.c_str(), nullptr));
    plane_ll.push_back(std::strtod(plane_text.c_str(), nullptr));
    std::remove(file.c_str());
  }
  // Far from the origin the terms, and their rounding, grow with |LL|: the
  // bound is max(2.4e-6, 1e-9 |LL|) nats per point (spec/api.md 4.3.1).
  const auto bound = [](double reference) { return std::max(2.4e-6, 1e-9 * std::fabs(reference)); };
  for (std::size_t i = 1; i < ll.size(); ++i) {
    EXPECT_NEAR(ll[i], ll[0], bound(ll[0])) << "kernel " << i << " vs sse2";
    EXPECT_NEAR(plane_ll[i], plane_ll[0], bound(plane_ll[0])) << "1 km plane: kernel " << i << " vs sse2";
  }
  std::printf("kernels vs sse2: frame %.2e, 1 km plane %.2e (LL %.6g, %.6g)\n", std::fabs(ll.back() - ll[0]),
              std::fabs(plane_ll.back() - plane_ll[0]), ll[0], plane_ll[0]);
}
