// How good a model is against the frame it came from (the paper's metrics).
#pragma once

#include <cstddef>
#include <cstdint>

#include "sogmm/camera.hpp"
#include "sogmm/gmm.hpp"
#include "sogmm/point_cloud.hpp"

namespace sogmm {

/// Peak signal-to-noise ratios of regressed gray against the frame's gray.
struct PsnrResult {
  /// Honest: 10 log10(data_range^2 / mse), only pixels valid in the ground
  /// truth, over the decimated canvas. The headline figure.
  double psnr = 0.0;
  /// As the authors' evaluation computes it: data range 2 always (scikit-
  /// image infers it from the -1 empty pixels, whatever the gray's actual
  /// range) and every pixel of the decimated canvas counted, the empty ones as
  /// perfect. Add 13.98 dB to compare with the paper's printed values (their
  /// benchmark also keeps the 640x480 canvas).
  double psnr_paper = 0.0;
  double mse = 0.0;         ///< mean squared gray error over valid pixels
  double data_range = 1.0;  ///< the data range `psnr` used (see psnr_images)
};

/// Regresses gray at every ground-truth point, projects regressed and true gray
/// into two images of `camera` (z-buffer, empty = -1) and compares them with
/// psnr_images(..., data_range).
/// `truth` holds the ground-truth points (x, y, z, gray) in the camera frame.
PsnrResult psnr(const Gmm& gmm, const PointsView& truth, const Camera& camera, double data_range = 1.0);

/// PSNR from two images with -1 for empty pixels. Honest: pixels where
/// `truth` >= 0, with `data_range` as the peak: 1 (default) for gray in
/// [0, 1]; 0 = the actual range of the valid truth pixels (max - min, e.g. for
/// normalised thermal data; a constant image then has range 0 and PSNR
/// +infinity only if it is matched exactly, else Error(InvalidData)). Paper:
/// data range 2, all pixels. `psnr` is finite whenever the images differ on a
/// valid pixel, for any finite data_range (computed as 20 log10(data_range) -
/// 10 log10(mse), so data_range^2 never overflows); +infinity means they
/// match exactly. Throws Error(InvalidArgument) for a negative or
/// non-finite data_range, Error(InvalidData) without a valid pixel.
PsnrResult psnr_images(const float* truth, const float* estimate, std::size_t pixels, double data_range = 1.0);

/// Geometric reconstruction quality from samples.
struct ReconstructionResult {
  /// Mean distance from each sampled point to the nearest ground-truth point (m).
  double mre = 0.0;
  /// Named as in the authors' code, where the names are swapped relative to the
  /// usual convention: `precision` = fraction of ground-truth points within
  /// the threshold of a sample (usually called recall), `recall` = fraction of
  /// samples within the threshold of a ground-truth point (usually precision).
  double precision = 0.0;
  double recall = 0.0;
  double fscore = 0.0;  ///< harmonic mean of the two (unaffected by naming)
};

/// Draws as many 3-D samples as there are ground-truth points (seeded) and
/// computes MRE and precision/recall/F-score at `threshold` metres with exact
/// nearest neighbours (k-d tree).
ReconstructionResult reconstruction_metrics(const Gmm& gmm, const PointsView& truth,
                                            double threshold = 0.01, std::uint64_t seed = 0);

/// Same, against an explicit reconstructed cloud (rows of 3 or 4 floats given
/// by `stride`), e.g. the output of another map representation.
ReconstructionResult compare_clouds(const float* reconstructed, std::size_t n, int stride,
                                    const PointsView& truth, double threshold = 0.01);

}  // namespace sogmm
