// merge (support-size re-weighting), rigid transform (closed form and density
// invariance), paper byte count, and validate().
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <initializer_list>
#include <vector>

#include "sogmm/inference.hpp"
#include "sogmm/model.hpp"
#include "pose_util.hpp"
#include "test_util.hpp"

using sogmm_test::cov_of;
using sogmm_test::mean_of;
using sogmm_test::set_component;

namespace {

Eigen::Matrix4d spd(double a, double b, double c, double d, double off) {
  Eigen::Matrix4d m = Eigen::Vector4d(a, b, c, d).asDiagonal();
  m(0, 1) = m(1, 0) = off;
  m(2, 3) = m(3, 2) = -off / 2;
  m(0, 3) = m(3, 0) = off / 3;
  return m;
}

sogmm::Gmm model_a() {
  sogmm::Gmm g;
  g.resize(2);
  set_component(g, 0, 0.25, Eigen::Vector4d(0.1, 0.2, 1.0, 0.3), spd(0.04, 0.03, 0.02, 0.01, 0.005));
  set_component(g, 1, 0.75, Eigen::Vector4d(-0.3, 0.0, 1.5, 0.6), spd(0.02, 0.05, 0.03, 0.02, -0.004));
  g.support_size = 100;
  return g;
}
sogmm::Gmm model_b() {
  sogmm::Gmm g;
  g.resize(1);
  set_component(g, 0, 1.0, Eigen::Vector4d(0.5, -0.5, 2.0, 0.9), spd(0.06, 0.02, 0.04, 0.03, 0.01));
  g.support_size = 300;
  return g;
}

}  // namespace

namespace {
// The weights of m, each within 1e-7 of `want` (exact ratios stored as float).
void expect_weights(const sogmm::Gmm& m, std::initializer_list<double> want) {
  ASSERT_EQ(m.weights.size(), want.size());
  std::size_t k = 0;
  for (double w : want) {
    EXPECT_NEAR(m.weights[k], w, 1e-7) << "weight " << k;
    ++k;
  }
}
}  // namespace

TEST(Merge, ReweightsBySupportSize) {
  const sogmm::Gmm a = model_a(), b = model_b();
  const sogmm::Gmm m = sogmm::merge(a, b);
  ASSERT_EQ(m.size(), 3u);
  EXPECT_EQ(m.support_size, 400u);
  // 0.25 * 100/400, 0.75 * 100/400, 1 * 300/400
  expect_weights(m, {0.0625, 0.1875, 0.75});
  for (int i = 0; i < 8; ++i) EXPECT_EQ(m.means[i], a.means[i]);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(m.means[8 + i], b.means[i]);
  for (int i = 0; i < 32; ++i) EXPECT_EQ(m.covariances[i], a.covariances[i]);
  for (int i = 0; i < 16; ++i) EXPECT_EQ(m.covariances[32 + i], b.covariances[i]);
  EXPECT_TRUE(sogmm_test::model_is_valid(m));
}

TEST(Merge, ZeroSupportCountsEqually) {
  sogmm::Gmm a = model_a(), b = model_b();
  a.support_size = 0;
  b.support_size = 0;
  const sogmm::Gmm m = sogmm::merge(a, b);
  ASSERT_EQ(m.size(), 3u);
  EXPECT_EQ(m.support_size, 0u);
  expect_weights(m, {0.125, 0.375, 0.5});
}

TEST(Merge, DensityIsSupportWeightedAverage) {
  // p_merged = (S_a p_a + S_b p_b) / (S_a + S_b) at any point.
  const sogmm::Gmm a = model_a(), b = model_b(), m = sogmm::merge(a, b);
  const float x[12] = {0.1f, 0.2f, 1.1f, 0.3f, 0.4f, -0.4f, 1.9f, 0.8f, 0.0f, 0.0f, 1.5f, 0.5f};
  double la[3], lb[3], lm[3];
  sogmm::score_samples(a, x, 3, 4, la);
  sogmm::score_samples(b, x, 3, 4, lb);
  sogmm::score_samples(m, x, 3, 4, lm);
  for (int i = 0; i < 3; ++i) {
    const double e = std::log(0.25 * std::exp(la[i]) + 0.75 * std::exp(lb[i]));
    EXPECT_NEAR(lm[i], e, 1e-5) << i;
  }
}

using sogmm_test::pose_of;

TEST(Transform, ClosedForm) {
  const sogmm::Gmm a = model_a();
  const Eigen::Matrix3d r =
      (Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(-0.4, Eigen::Vector3d::UnitX()) *
       Eigen::AngleAxisd(1.1, Eigen::Vector3d::UnitY()))
          .toRotationMatrix();
  const Eigen::Vector3d t(1.0, -2.0, 0.5);
  const sogmm::Gmm b = sogmm::transform(a, pose_of(r, t));
  ASSERT_EQ(b.size(), a.size());
  EXPECT_EQ(b.support_size, a.support_size);
  Eigen::Matrix4d big = Eigen::Matrix4d::Identity();
  big.topLeftCorner<3, 3>() = r;
  for (std::size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(b.weights[k], a.weights[k]);
    Eigen::Vector4d mu = mean_of(a, k);
    Eigen::Vector4d emu = mu;
    emu.head<3>() = r * mu.head<3>() + t;
    const Eigen::Matrix4d ecov = big * cov_of(a, k) * big.transpose();
    EXPECT_LT((mean_of(b, k) - emu).cwiseAbs().maxCoeff(), 1e-5) << "component " << k;
    EXPECT_LT((cov_of(b, k) - ecov).cwiseAbs().maxCoeff(), 1e-6) << "component " << k;
  }
  EXPECT_TRUE(sogmm_test::model_is_valid(b));
}

// The identity is no move at all: every bit stays, a -0 coordinate too (the
// arithmetic would give +0). A map merge or load at the identity relies on it.
TEST(Transform, IdentityKeepsEveryBit) {
  sogmm::Gmm a = model_a();
  a.means[0] = -0.0f;
  const sogmm::Gmm b = sogmm::transform(a, pose_of(Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero()));
  EXPECT_TRUE(sogmm_test::bit_identical(a, b));
  EXPECT_TRUE(std::signbit(b.means[0]));
  // Not the identity by 1e-300 in translation: arithmetic, so -0 + 1e-300 rounds away from -0.
  const sogmm::Gmm c = sogmm::transform(a, pose_of(Eigen::Matrix3d::Identity(), Eigen::Vector3d(1e-300, 0, 0)));
  EXPECT_FALSE(std::signbit(c.means[0]));
}

// A moved covariance is stored exactly symmetric (bitwise), as every model
// the library makes: an asymmetric one in memory is not what the file keeps
// (the writer stores the symmetric part), so a map built with it would change
// when saved and loaded again (issue 36 saw that; transform was not the
// cause, this guards it). 200 rotations about fixed axes, no randomness.
TEST(Transform, CovariancesAreExactlySymmetric) {
  const sogmm::Gmm a = model_a();
  for (int n = 0; n < 200; ++n) {
    const Eigen::Vector3d axis(std::sin(0.37 * n), std::cos(0.91 * n), 0.3 + std::sin(1.3 * n));
    const Eigen::Matrix3d r = Eigen::AngleAxisd(0.031 * n + 0.1, axis.normalized()).toRotationMatrix();
    const sogmm::Gmm b = sogmm::transform(a, pose_of(r, Eigen::Vector3d(0.5 * n, -1.0, 2.0)));
    for (std::size_t k = 0; k < b.size(); ++k) {
      const float* c = b.covariance(k);
      for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j)
          ASSERT_EQ(c[4 * i + j], c[4 * j + i]) << "rotation " << n << " component " << k << " entry " << i << j;
    }
  }
}

// A thin component (a 100 m x 100 m sheet 1 cm thick, gray variance 1: its
// spatial eigenvalues 1e4 and 1e-4 are 1e8 apart, past float32's 2^24) is
// exact in float32 while axis-aligned; turned by a pose, rounding R Sigma R^T
// entry by entry loses the small eigenvalue, and for some rotations gives an
// indefinite matrix that could then not be saved, scored or sampled (fuzz_api:
// a fit, a transform, a save failing not_spd). Every rotation must give a
// valid model, and its thin direction must stay thin: the stored matrix's
// variance along the rotated normal within a factor 4 of 1e-4 (a float32
// step of an entry near 1e4 is 2^-10 = 9.8e-4, ten times that variance, so
// plain rounding misses it by up to tens of times or makes it negative; the
// store picks the roundings whose errors cancel along the normal). The same
// on every kernel: transform is scalar double arithmetic.
TEST(Transform, ThinComponentStaysValidAndThinUnderEveryRotation) {
  sogmm::Gmm thin;
  thin.resize(1);
  set_component(thin, 0, 1.0, Eigen::Vector4d(1.0, 2.0, 3.0, 0.5),
                Eigen::Vector4d(1e4, 1e4, 1e-4, 1.0).asDiagonal().toDenseMatrix());
  thin.support_size = 10;
  ASSERT_NO_THROW(sogmm::validate(thin));
  int was_indefinite = 0;
  for (int n = 0; n < 200; ++n) {
    const Eigen::Vector3d axis(std::sin(0.37 * n), std::cos(0.91 * n), 0.3 + std::sin(1.3 * n));
    const Eigen::Matrix3d r = Eigen::AngleAxisd(0.031 * n + 0.1, axis.normalized()).toRotationMatrix();
    const sogmm::Gmm b = sogmm::transform(thin, pose_of(r, Eigen::Vector3d(0.5, -1.0, 2.0)));
    ASSERT_NO_THROW(sogmm::validate(b)) << "rotation " << n;
    // What plain rounding of R Sigma R^T would have stored (counted to show
    // the case is reached: the test is void if no rotation needs the store).
    Eigen::Matrix4d a = Eigen::Matrix4d::Identity();
    a.topLeftCorner<3, 3>() = r;
    const Eigen::Matrix4d exact = a * cov_of(thin, 0) * a.transpose();
    const Eigen::Matrix4d plain = exact.cast<float>().cast<double>();
    if (Eigen::LLT<Eigen::Matrix4d>(0.5 * (plain + plain.transpose())).info() != Eigen::Success) ++was_indefinite;
    Eigen::Vector4d normal = Eigen::Vector4d::Zero();
    normal.head<3>() = r.col(2);
    const double along = normal.dot(cov_of(b, 0) * normal);
    EXPECT_GT(along, 0.25e-4) << "rotation " << n;
    EXPECT_LT(along, 4e-4) << "rotation " << n;
  }
  EXPECT_GT(was_indefinite, 0) << "no rotation made plain rounding indefinite: the case is not exercised";
}

TEST(Transform, DensityAndRegressionInvariant) {
  // p'(T x) = p(x) (|det R| = 1) and the regressed gray moves with the point.
  const sogmm::Gmm a = model_a();
  const Eigen::Matrix3d r = Eigen::AngleAxisd(2.0, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Vector3d t(-0.3, 0.8, 2.0);
  const sogmm::Gmm b = sogmm::transform(a, pose_of(r, t));
  const std::vector<float> x = {0.1f, 0.2f, 1.1f, 0.3f, -0.2f, 0.1f, 1.4f, 0.5f, 0.3f, -0.1f, 1.2f, 0.7f};
  std::vector<float> y(x.size()), x3, y3;
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d p(x[4 * i], x[4 * i + 1], x[4 * i + 2]);
    const Eigen::Vector3d q = r * p + t;
    for (int d = 0; d < 3; ++d) {
      y[4 * i + d] = static_cast<float>(q(d));
      x3.push_back(x[4 * i + d]);
      y3.push_back(y[4 * i + d]);
    }
    y[4 * i + 3] = x[4 * i + 3];
  }
  double la[3], lb[3];
  sogmm::score_samples(a, x.data(), 3, 4, la);
  sogmm::score_samples(b, y.data(), 3, 4, lb);
  float ga[3], gb[3], va[3], vb[3];
  sogmm::regress_gray(a, x3.data(), 3, ga, va);
  sogmm::regress_gray(b, y3.data(), 3, gb, vb);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(lb[i], la[i], 2e-3) << i;  // float32 rounding of rotated points and parameters
    EXPECT_NEAR(gb[i], ga[i], 1e-4) << i;
    EXPECT_NEAR(vb[i], va[i], 1e-4) << i;
  }
}

TEST(Transform, SamplesOfTransformedModelMatchTransformedSamples) {
  // Moments of samples from transform(g) equal those of transformed samples of g.
  const sogmm::Gmm a = model_b();
  const Eigen::Matrix3d r = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d t(1, 2, 3);
  const sogmm::Gmm b = sogmm::transform(a, pose_of(r, t));
  const std::size_t n = 50000;
  std::vector<float> sa(4 * n), sb(4 * n);
  sogmm::sample(a, n, 1, 4, sa.data());
  sogmm::sample(b, n, 2, 4, sb.data());
  Eigen::Vector3d ma = Eigen::Vector3d::Zero(), mb = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    ma += r * Eigen::Vector3d(sa[4 * i], sa[4 * i + 1], sa[4 * i + 2]) + t;
    mb += Eigen::Vector3d(sb[4 * i], sb[4 * i + 1], sb[4 * i + 2]);
  }
  ma /= n;
  mb /= n;
  // Rz(90) maps (0.5, -0.5, 2) to (0.5, 0.5, 2); plus t: (1.5, 2.5, 5).
  const Eigen::Vector3d e(1.5, 2.5, 5.0);
  for (int d = 0; d < 3; ++d) {
    EXPECT_NEAR(ma(d), e(d), 5 * std::sqrt(0.06 / n));
    EXPECT_NEAR(mb(d), e(d), 5 * std::sqrt(0.06 / n));
  }
}

TEST(Transform, RejectsNonRotation) {
  const sogmm::Gmm a = model_a();
  Eigen::Matrix3d s = Eigen::Matrix3d::Identity();
  s(0, 0) = 2.0;  // scaling
  sogmm_test::expect_error([&] { sogmm::transform(a, pose_of(s, Eigen::Vector3d::Zero())); },
                           sogmm::ErrorCode::InvalidArgument, {"rotation"}, "scaling pose");
  Eigen::Matrix3d refl = Eigen::Matrix3d::Identity();
  refl(2, 2) = -1.0;  // reflection: orthogonal but det = -1
  sogmm_test::expect_error([&] { sogmm::transform(a, pose_of(refl, Eigen::Vector3d::Zero())); },
                           sogmm::ErrorCode::InvalidArgument, {"rotation"}, "reflection pose");
}

TEST(ModelBytes, PaperCount) {
  EXPECT_EQ(sogmm::paper_model_bytes(model_a()), 4u * 2u * 15u);
  EXPECT_EQ(sogmm::paper_model_bytes(sogmm::merge(model_a(), model_b())), 180u);
}

TEST(Validate, AcceptsValidRejectsBroken) {
  // gmm.hpp documents "Error(InvalidData or Numeric)" without a mapping.
  const auto kEither = {sogmm::ErrorCode::InvalidData, sogmm::ErrorCode::Numeric};
  const sogmm::Gmm good = model_a();
  EXPECT_TRUE(sogmm_test::model_is_valid(good));
  EXPECT_NO_THROW(sogmm::validate(good));

  sogmm::Gmm w = good;
  w.weights[1] = 0.5f;  // sums to 0.75
  EXPECT_FALSE(sogmm::validation_error(w).empty());
  sogmm_test::expect_error_codes([&] { sogmm::validate(w); }, kEither, {"weight"},
                           "weights not summing to 1");

  sogmm::Gmm nan = good;
  nan.means[5] = std::nanf("");
  sogmm_test::expect_error_codes([&] { sogmm::validate(nan); }, kEither,
                           {"finite", "nan"}, "NaN mean");

  sogmm::Gmm npd = good;
  set_component(npd, 1, 0.75, mean_of(good, 1), Eigen::Vector4d(0.02, -0.01, 0.03, 0.02).asDiagonal().toDenseMatrix());
  const std::string msg = sogmm::validation_error(npd);
  EXPECT_NE(msg.find('1'), std::string::npos) << "message should name component 1: " << msg;
  sogmm_test::expect_error_codes([&] { sogmm::validate(npd); }, kEither,
                           {"positive definite", "positive-definite", "cholesky"}, "non-SPD covariance");

  sogmm::Gmm asym = good;
  asym.covariances[16 + 1] += 0.01f;
  sogmm_test::expect_error_codes([&] { sogmm::validate(asym); }, kEither, {"symmetric"},
                           "asymmetric covariance");

  sogmm::Gmm empty;
  EXPECT_FALSE(sogmm::validation_error(empty).empty());
  sogmm::Gmm sizes = good;
  sizes.means.pop_back();
  EXPECT_FALSE(sogmm::validation_error(sizes).empty());
}

// Model::key_values by key (sogmm/model.hpp): first match wins, set replaces
// the first entry in place or appends, erase removes every entry.
TEST(ModelValues, FindSetErase) {
  sogmm::Model m;
  m.key_values = {{"a", "1"}, {"b", "2"}, {"a", "3"}};
  ASSERT_NE(sogmm::find_value(m, "a"), nullptr);
  EXPECT_EQ(*sogmm::find_value(m, "a"), "1");
  EXPECT_EQ(sogmm::find_value(m, "c"), nullptr);
  sogmm::set_value(m, "b", "20");
  sogmm::set_value(m, "c", "4");
  const std::vector<std::pair<std::string, std::string>> set = {{"a", "1"}, {"b", "20"}, {"a", "3"}, {"c", "4"}};
  EXPECT_EQ(m.key_values, set);
  sogmm::erase_value(m, "a");
  const std::vector<std::pair<std::string, std::string>> erased = {{"b", "20"}, {"c", "4"}};
  EXPECT_EQ(m.key_values, erased);
  EXPECT_EQ(sogmm::coordinate_frame(m), "camera");
  sogmm::set_value(m, sogmm::kCoordinateFrameKey, "world");
  EXPECT_EQ(sogmm::coordinate_frame(m), "world");
}
