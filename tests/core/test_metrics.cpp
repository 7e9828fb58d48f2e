// psnr_images, psnr (end to end), compare_clouds, reconstruction_metrics.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "sogmm/inference.hpp"
#include "sogmm/metrics.hpp"
#include "test_util.hpp"

TEST(Metrics, PsnrImagesHandComputed) {
  // Empty pixels (-1) coincide in both images, as when both are projected
  // from the same points.
  const float truth[4] = {0.5f, 0.2f, -1.0f, 0.8f};
  const float est[4] = {0.6f, 0.2f, -1.0f, 0.8f};
  const sogmm::PsnrResult r = sogmm::psnr_images(truth, est, 4);
  const double se = (0.6 - 0.5) * (0.6 - 0.5);  // as the floats hold them
  const double d = static_cast<double>(0.6f) - static_cast<double>(0.5f);
  EXPECT_NEAR(r.mse, d * d / 3.0, 1e-9);          // valid pixels: 3
  EXPECT_NEAR(r.psnr, 10.0 * std::log10(1.0 / (d * d / 3.0)), 1e-4);       // 24.77 dB
  EXPECT_NEAR(r.psnr_paper, 10.0 * std::log10(4.0 / (d * d / 4.0)), 1e-4);  // 32.04 dB
  EXPECT_NEAR(r.psnr, 24.771, 1e-3);
  EXPECT_NEAR(r.psnr_paper, 32.041, 1e-3);
  (void)se;
}

TEST(Metrics, PsnrImagesEmptyPixelsInEstimate) {
  // An estimate pixel left empty where truth is valid counts (-1 vs 0.5) in
  // both figures: honest over 2 valid pixels, paper over all 3 with range 2.
  const float truth[3] = {0.5f, 0.25f, -1.0f};
  const float est[3] = {-1.0f, 0.25f, -1.0f};
  const sogmm::PsnrResult r = sogmm::psnr_images(truth, est, 3);
  EXPECT_NEAR(r.mse, 2.25 / 2.0, 1e-9);
  EXPECT_NEAR(r.psnr, 10.0 * std::log10(1.0 / 1.125), 1e-6);
  EXPECT_NEAR(r.psnr_paper, 10.0 * std::log10(4.0 / 0.75), 1e-6);
}

TEST(Metrics, PsnrEndToEndConstantGrayModel) {
  // A single component with Sigma_gx = 0 regresses gray = mu_g = 0.5 everywhere.
  sogmm::Gmm g;
  g.resize(1);
  sogmm_test::set_component(g, 0, 1.0, Eigen::Vector4d(0, 0, 1, 0.5), 0.01 * Eigen::Matrix4d::Identity());
  const sogmm::Camera cam{4, 2, 1.0, 1.0, 1.0, 0.0};
  // Three points at distinct pixels (u = round(x/z + 1), v = round(y/z)), gray 0.3, 0.5, 0.9.
  const std::vector<float> pts = {-1.0f, 0.0f, 1.0f, 0.3f,  //  (0, 0)
                                  0.0f, 0.0f, 1.0f, 0.5f,   //  (1, 0)
                                  2.0f, 2.0f, 2.0f, 0.9f};  //  (2, 1)
  const sogmm::PsnrResult r = sogmm::psnr(g, {pts.data(), 3}, cam);
  const double mse = (0.04 + 0.0 + 0.16) / 3.0;
  EXPECT_NEAR(r.mse, mse, 1e-6);
  EXPECT_NEAR(r.psnr, 10.0 * std::log10(1.0 / mse), 1e-4);
  EXPECT_NEAR(r.psnr_paper, 10.0 * std::log10(4.0 / (0.2 / 8.0)), 1e-4);  // 8 pixels, range 2
}

TEST(Metrics, CompareCloudsHandComputed) {
  // Truth: (0,0,0), (1,0,0), (0,1,0). Reconstructed: (0.003, 0.004, 0) at
  // 0.005 from (0,0,0); (1, 0.02, 0) at 0.02 from (1,0,0). Threshold 0.01.
  // MRE = 0.0125; samples within threshold: 1/2 ("recall" in the authors'
  // naming); truth points within threshold of a sample: 1/3 ("precision");
  // F = 2 (1/3)(1/2) / (1/3 + 1/2) = 0.4.
  const std::vector<float> truth = {0, 0, 0, 0.1f, 1, 0, 0, 0.2f, 0, 1, 0, 0.3f};
  const std::vector<float> rec3 = {0.003f, 0.004f, 0.0f, 1.0f, 0.02f, 0.0f};
  const std::vector<float> rec4 = {0.003f, 0.004f, 0.0f, 0.9f, 1.0f, 0.02f, 0.0f, 0.9f};
  for (int stride : {3, 4}) {
    const auto& rec = stride == 3 ? rec3 : rec4;
    const sogmm::ReconstructionResult r = sogmm::compare_clouds(rec.data(), 2, stride, {truth.data(), 3}, 0.01);
    EXPECT_NEAR(r.mre, 0.0125, 1e-7) << "stride " << stride;
    EXPECT_NEAR(r.recall, 0.5, 1e-12) << "stride " << stride;
    EXPECT_NEAR(r.precision, 1.0 / 3.0, 1e-12) << "stride " << stride;
    EXPECT_NEAR(r.fscore, 0.4, 1e-12) << "stride " << stride;
  }
  // Threshold above every distance: everything matched except truth point 3.
  const sogmm::ReconstructionResult r = sogmm::compare_clouds(rec3.data(), 2, 3, {truth.data(), 3}, 0.05);
  EXPECT_NEAR(r.recall, 1.0, 1e-12);
  EXPECT_NEAR(r.precision, 2.0 / 3.0, 1e-12);
  EXPECT_NEAR(r.fscore, 0.8, 1e-12);
}

TEST(Metrics, ReconstructionMetricsOfTightModel) {
  // Ground truth: 2000 points from a component of 1 mm; samples of the same
  // component fall within 1 cm of a truth point: MRE small, scores 1.
  sogmm::Gmm g;
  g.resize(1);
  Eigen::Matrix4d c = 1e-6 * Eigen::Matrix4d::Identity();
  sogmm_test::set_component(g, 0, 1.0, Eigen::Vector4d(0.2, 0.1, 1.5, 0.5), c);
  const std::vector<float> truth = sogmm_test::draw_mixture({Eigen::Vector4d(0.2, 0.1, 1.5, 0.5)}, {c}, {2000}, 8);
  const sogmm::ReconstructionResult r = sogmm::reconstruction_metrics(g, {truth.data(), 2000}, 0.01, 3);
  EXPECT_GT(r.mre, 0.0);
  EXPECT_LT(r.mre, 0.001);
  EXPECT_DOUBLE_EQ(r.precision, 1.0);
  EXPECT_DOUBLE_EQ(r.recall, 1.0);
  EXPECT_DOUBLE_EQ(r.fscore, 1.0);
  const sogmm::ReconstructionResult again = sogmm::reconstruction_metrics(g, {truth.data(), 2000}, 0.01, 3);
  EXPECT_EQ(r.mre, again.mre);
}
