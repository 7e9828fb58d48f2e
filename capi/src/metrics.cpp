// Image metrics: the PSNR of a rendered gray image against the frame's.
#include "internal.hpp"
#include "sogmm/checked.hpp"
#include "sogmm/metrics.hpp"

extern "C" {

SOGMM_API sogmm_status sogmm_psnr_images_f32(const float* truth, const float* estimate, size_t pixels,
                                             double data_range, double* psnr_out, double* psnr_paper_out) {
  SOGMM_TRY {
    sogmm_capi::require_nonnull(truth, "truth");
    sogmm_capi::require_nonnull(estimate, "estimate");
    sogmm_capi::require_nonnull(psnr_out, "psnr_out");
    sogmm_capi::require_finite(truth, pixels, "truth");
    sogmm_capi::require_finite(estimate, pixels, "estimate");
    const sogmm::PsnrResult r = sogmm::psnr_images(truth, estimate, pixels, data_range);
    *psnr_out = r.psnr;
    if (psnr_paper_out) *psnr_paper_out = r.psnr_paper;
  }
  SOGMM_CATCH
}

}  // extern "C"
