package sogmm

// #include "sogmm/sogmm.h"
import "C"

import "fmt"

// PSNR holds both figures of PSNRImages, in dB (+Inf for identical images).
type PSNR struct {
	// PSNR is 10 log10(dataRange^2 / MSE) over the pixels valid in the truth (>= 0).
	PSNR float64
	// Paper is the authors' evaluation: range 2, every pixel counted (empty ones as perfect).
	Paper float64
}

// PSNRImages is the PSNR of the gray image estimate against truth (the same
// number of pixels, -1 marking an empty one, as `sogmm eval` draws a
// rendering of the model against the frame's gray). dataRange is the peak: 1
// for gray in [0, 1], any other peak for other data, or 0 for the actual
// range of the valid truth pixels (max - min).
//
// Errors: lengths that differ -> ErrInvalidArg; dataRange negative or not
// finite -> ErrInvalidArg (from the library, naming it); NaN/Inf pixels, no
// valid truth pixel, or range 0 on a constant truth not matched exactly ->
// ErrInvalidData.
func PSNRImages(truth, estimate []float32, dataRange float64) (PSNR, error) {
	if err := abiOnce(); err != nil {
		return PSNR{}, err
	}
	if len(truth) != len(estimate) {
		return PSNR{}, invalidArg("truth has %d pixels and estimate %d: they must be the same size",
			len(truth), len(estimate))
	}
	var psnr, paper C.double
	// An empty image has a nil data pointer; C would report a NULL argument
	// instead of "no valid pixel", so give it a valid address.
	var empty float32
	t, e := floats(truth), floats(estimate)
	if len(truth) == 0 {
		t, e = (*C.float)(&empty), (*C.float)(&empty)
	}
	err := call(func() C.sogmm_status {
		return C.sogmm_psnr_images_f32(t, e, C.size_t(len(truth)), C.double(dataRange), &psnr, &paper)
	})
	if err != nil {
		return PSNR{}, err
	}
	return PSNR{PSNR: float64(psnr), Paper: float64(paper)}, nil
}

// String prints both figures.
func (p PSNR) String() string { return fmt.Sprintf("PSNR %.4f dB (paper %.4f dB)", p.PSNR, p.Paper) }
