package sogmm

// #include "sogmm/sogmm.h"
import "C"

import (
	"context"
	"runtime"
	"unsafe"
)

// Frame is one RGB-D frame: raw depth (OptDepthScale units per metre, 0 = no
// reading) and exactly one of Gray8, RGB8 (interleaved) or GrayF32, all
// row-major Width x Height, with the full-size pinhole intrinsics.
type Frame struct {
	Depth          []uint16
	Gray8, RGB8    []uint8
	GrayF32        []float32
	Width, Height  uint32
	Fx, Fy, Cx, Cy float64
}

// colorArgs checks every slice length against Width and Height (C cannot
// see them) and returns the color pointer and its SOGMM_COLOR_* format.
func (f *Frame) colorArgs() (unsafe.Pointer, C.int32_t, error) {
	pixels := int(f.Width) * int(f.Height)
	if len(f.Depth) != pixels {
		return nil, 0, invalidArg("depth has %d values, width * height = %d", len(f.Depth), pixels)
	}
	var color unsafe.Pointer
	var format C.int32_t
	given, want := 0, pixels
	switch {
	case f.Gray8 != nil && f.RGB8 == nil && f.GrayF32 == nil:
		color, format, given = unsafe.Pointer(unsafe.SliceData(f.Gray8)), C.SOGMM_COLOR_GRAY8, len(f.Gray8)
	case f.RGB8 != nil && f.Gray8 == nil && f.GrayF32 == nil:
		color, format, given, want = unsafe.Pointer(unsafe.SliceData(f.RGB8)), C.SOGMM_COLOR_RGB8, len(f.RGB8), 3*pixels
	case f.GrayF32 != nil && f.Gray8 == nil && f.RGB8 == nil:
		color, format, given = unsafe.Pointer(unsafe.SliceData(f.GrayF32)), C.SOGMM_COLOR_GRAY_F32, len(f.GrayF32)
	default:
		return nil, 0, invalidArg("a frame needs exactly one of Gray8, RGB8, GrayF32")
	}
	if given != want {
		return nil, 0, invalidArg("color has %d values, the frame needs %d", given, want)
	}
	return color, format, nil
}

// handle makes the C frame (sogmm_frame_from_arrays, copying the pixels, with
// the intrinsics) that the fit, the map insert and Points hand to the
// library; the caller frees it with C.sogmm_frame_free.
func (f *Frame) handle() (*C.sogmm_frame, error) {
	color, format, err := f.colorArgs()
	if err != nil {
		return nil, err
	}
	var h *C.sogmm_frame
	err = call(func() C.sogmm_status {
		return C.sogmm_frame_from_arrays(&h, C.uint32_t(f.Width), C.uint32_t(f.Height),
			(*C.uint16_t)(unsafe.SliceData(f.Depth)), color, format)
	})
	runtime.KeepAlive(f)
	if err != nil {
		return nil, err
	}
	if err := call(func() C.sogmm_status {
		return C.sogmm_frame_set_intrinsics(h, C.double(f.Fx), C.double(f.Fy), C.double(f.Cx), C.double(f.Cy))
	}); err != nil {
		C.sogmm_frame_free(h)
		return nil, err
	}
	return h, nil
}

// FitRGBD fits one frame; decimation and depth range come from o; ctx and
// the progress func of o as Fit.
func FitRGBD(ctx context.Context, f Frame, o *Options) (*Model, error) {
	h, err := f.handle()
	if err != nil {
		return nil, err
	}
	defer C.sogmm_frame_free(h)
	return withProgress(ctx, o, func(o *Options) (*Model, error) {
		return newModel(o, func(out **C.sogmm_model, op *C.sogmm_options) C.sogmm_status {
			return C.sogmm_fit_frame(out, h, op)
		})
	})
}

// Points returns the points FitRGBD would fit, without fitting: N rows (x, y,
// z, gray) in the camera frame (decimation and depth range from o). A frame
// without a valid pixel gives an empty slice.
func (f Frame) Points(o *Options) ([]float32, error) {
	op, err := o.raw()
	if err != nil {
		return nil, err
	}
	h, err := f.handle()
	if err != nil {
		return nil, err
	}
	defer C.sogmm_frame_free(h)
	var n C.size_t
	fill := func(out []float32) error {
		return call(func() C.sogmm_status {
			return C.sogmm_frame_to_points_f32(floats(out), C.size_t(len(out)), &n, h, op)
		})
	}
	if err := fill(nil); err != nil { // capacity 0: only counts
		return nil, err
	}
	out := make([]float32, 4*int(n))
	err = fill(out)
	runtime.KeepAlive(o)
	if err != nil {
		return nil, err
	}
	return out, nil
}
