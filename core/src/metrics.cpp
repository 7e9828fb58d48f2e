// PSNR of regressed gray, and reconstruction error of sampled geometry.
#include "sogmm/metrics.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <nanoflann.hpp>

#include "sogmm/checked.hpp"
#include "sogmm/error.hpp"
#include "sogmm/inference.hpp"

namespace sogmm {
namespace {

// nanoflann adaptor over rows of `stride` floats whose first 3 are x, y, z.
struct CloudAdaptor {
  const float* data;
  std::size_t n;
  int stride;
  std::size_t kdtree_get_point_count() const { return n; }
  float kdtree_get_pt(std::size_t i, std::size_t dim) const { return data[stride * i + dim]; }
  template <class Box>
  bool kdtree_get_bbox(Box&) const { return false; }
};
using KdTree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, CloudAdaptor, double>,
                                                   CloudAdaptor, 3>;

// Distance from every query row to its nearest point of the indexed cloud.
std::vector<double> nearest_distances(const CloudAdaptor& index_cloud, const CloudAdaptor& queries) {
  KdTree tree(3, index_cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10));
  tree.buildIndex();
  std::vector<double> out(queries.n);
#pragma omp parallel for schedule(static)
  for (std::size_t i = 0; i < queries.n; ++i) {
    std::uint32_t idx;
    double d2;
    float q[3] = {queries.kdtree_get_pt(i, 0), queries.kdtree_get_pt(i, 1), queries.kdtree_get_pt(i, 2)};
    tree.knnSearch(q, 1, &idx, &d2);
    out[i] = std::sqrt(d2);
  }
  return out;
}

}  // namespace

PsnrResult psnr_images(const float* truth, const float* estimate, std::size_t pixels, double data_range) {
  require(std::isfinite(data_range) && data_range >= 0, ErrorCode::InvalidArgument,
          "PSNR: data range must be finite and >= 0 (0 = the ground truth's actual range), got " +
              checked::exact(data_range));
  double se_valid = 0.0, se_all = 0.0;
  double lo = INFINITY, hi = -INFINITY;
  std::size_t valid = 0;
  for (std::size_t i = 0; i < pixels; ++i) {
    const double d = static_cast<double>(truth[i]) - estimate[i];
    se_all += d * d;
    if (truth[i] >= 0.0f) {
      se_valid += d * d;
      ++valid;
      lo = std::min<double>(lo, truth[i]);
      hi = std::max<double>(hi, truth[i]);
    }
  }
  require(valid > 0, ErrorCode::InvalidData, "PSNR: the ground-truth image has no valid pixel");
  PsnrResult r;
  r.data_range = data_range > 0 ? data_range : hi - lo;
  r.mse = se_valid / static_cast<double>(valid);
  require(r.data_range > 0 || r.mse == 0, ErrorCode::InvalidData,
          "PSNR: the ground truth is constant, so its actual data range is 0: give the data range");
  const double mse_all = se_all / static_cast<double>(pixels);
  // Identical images: report infinity, as PSNR is unbounded.
  // Written as 20 log10(range) - 10 log10(mse): range^2 overflows to +inf for
  // a range above ~1e154 (and underflows to 0, -inf, below ~1e-154), while
  // each logarithm of a finite positive double is finite, so images that
  // differ always get a finite figure.
  r.psnr = r.mse > 0 ? 20.0 * std::log10(r.data_range) - 10.0 * std::log10(r.mse) : INFINITY;
  r.psnr_paper = mse_all > 0 ? 10.0 * std::log10(4.0 / mse_all) : INFINITY;
  return r;
}

PsnrResult psnr(const Gmm& gmm, const PointsView& truth, const Camera& camera, double data_range) {
  require_finite_points(truth, "ground-truth cloud");
  std::vector<float> xyz(3 * truth.size), gray(truth.size), regressed(truth.size);
  for (std::size_t i = 0; i < truth.size; ++i) {
    for (int j = 0; j < 3; ++j) xyz[3 * i + j] = truth[i][j];
    gray[i] = truth[i][3];
  }
  regress_gray(gmm, xyz.data(), truth.size, regressed.data(), nullptr);
  const std::vector<float> truth_image = project_to_image(truth, gray.data(), camera, -1.0f);
  const std::vector<float> estimate_image = project_to_image(truth, regressed.data(), camera, -1.0f);
  return psnr_images(truth_image.data(), estimate_image.data(), truth_image.size(), data_range);
}

ReconstructionResult compare_clouds(const float* reconstructed, std::size_t n, int stride, const PointsView& truth,
                                    double threshold) {
  require(stride >= 3, ErrorCode::InvalidArgument, "stride must be >= 3");
  require(n > 0 && reconstructed != nullptr, ErrorCode::InvalidData, "reconstructed cloud is empty");
  require_finite_points(truth, "ground-truth cloud");
  const CloudAdaptor rec{reconstructed, n, stride};
  const CloudAdaptor gt{truth.data, truth.size, 4};
  const std::vector<double> rec_to_gt = nearest_distances(gt, rec);
  const std::vector<double> gt_to_rec = nearest_distances(rec, gt);
  ReconstructionResult r;
  std::size_t rec_close = 0, gt_close = 0;
  double sum = 0.0;
  for (double d : rec_to_gt) {
    sum += d;
    rec_close += d < threshold;
  }
  for (double d : gt_to_rec) gt_close += d < threshold;
  r.mre = sum / static_cast<double>(n);
  // Authors' naming (swapped relative to the usual convention): see metrics.hpp.
  r.precision = static_cast<double>(gt_close) / static_cast<double>(truth.size);
  r.recall = static_cast<double>(rec_close) / static_cast<double>(n);
  r.fscore = (r.precision + r.recall) > 0 ? 2.0 * r.precision * r.recall / (r.precision + r.recall) : 0.0;
  return r;
}

ReconstructionResult reconstruction_metrics(const Gmm& gmm, const PointsView& truth, double threshold,
                                            std::uint64_t seed) {
  require_finite_points(truth, "ground-truth cloud");
  std::vector<float> samples(3 * truth.size);
  sample(gmm, truth.size, seed, 3, samples.data());
  return compare_clouds(samples.data(), truth.size, 3, truth, threshold);
}

}  // namespace sogmm
