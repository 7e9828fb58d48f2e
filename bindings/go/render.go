package sogmm

// #include "sogmm/sogmm.h"
import "C"

import "fmt"

// Camera holds the pinhole intrinsics of a rendered image: pixel (u, v)
// looks along ((u - Cx) / Fx, (v - Cy) / Fy, 1) in the camera's frame.
type Camera struct {
	Width, Height  uint32
	Fx, Fy, Cx, Cy float64
}

// Rendered holds rendered images, row-major Width x Height: the first
// surface's depth (camera z, metres), the gray regressed there and its
// variance; NaN where the model shows nothing.
type Rendered struct {
	Width, Height         uint32
	Depth, Gray, Variance []float32
}

// renderInto allocates the three images (after the pixel limit of sogmm.h,
// so that no huge buffer is allocated for a call that must fail) and runs
// call with them.
func renderInto(cam Camera, call func(depth, gray, variance *C.float) error) (*Rendered, error) {
	pixels := uint64(cam.Width) * uint64(cam.Height)
	if pixels > C.SOGMM_MAX_RENDER_PIXELS {
		return nil, &Error{Status: ErrLimit,
			Message: fmt.Sprintf("render: %d x %d pixels exceed %d", cam.Width, cam.Height, C.SOGMM_MAX_RENDER_PIXELS)}
	}
	r := &Rendered{Width: cam.Width, Height: cam.Height, Depth: make([]float32, pixels),
		Gray: make([]float32, pixels), Variance: make([]float32, pixels)}
	if pixels == 0 { // the C call names the empty size
		return nil, call(nil, nil, nil)
	}
	if err := call(floats(r.Depth), floats(r.Gray), floats(r.Variance)); err != nil {
		return nil, err
	}
	return r, nil
}

func posePtr(pose *[16]float64) *C.double {
	if pose == nil {
		return nil
	}
	return (*C.double)(&pose[0])
}
