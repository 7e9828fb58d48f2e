package sogmm

// #include "sogmm/sogmm.h"
import "C"

import (
	"context"
	"runtime"
)

// FitWarm fits n points (rows of x, y, z, gray) starting from initial, a
// model of an earlier, overlapping cloud already moved into these points'
// frame (e.g. the previous frame's model moved with Transform by the relative
// pose). Self-organizing: components initial no longer explains are dropped
// and new ones are added for the novel points; with OptNComponents = K, EM
// runs from initial as given (K must be its size). Needs OptNInit 1; initial
// is not changed.
//
// ctx and the progress func of o as Fit.
func FitWarm(ctx context.Context, points []float32, initial *Model, o *Options) (*Model, error) {
	n, err := rowsOf(points, 4, "points")
	if err != nil {
		return nil, err
	}
	if initial == nil || initial.ptr == nil {
		return nil, ErrClosed
	}
	defer runtime.KeepAlive(initial)
	return withProgress(ctx, o, func(o *Options) (*Model, error) {
		return newModel(o, func(out **C.sogmm_model, op *C.sogmm_options) C.sogmm_status {
			return C.sogmm_fit_points_f32(out, floats(points), C.size_t(n), initial.ptr, op)
		})
	})
}
