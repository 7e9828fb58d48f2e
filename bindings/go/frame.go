package sogmm

// #include "sogmm/sogmm.h"
import "C"

import (
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

// FitRGBD fits one frame; decimation and depth range come from o.
func FitRGBD(f Frame, o *Options) (*Model, error) {
	color, format, err := f.colorArgs()
	if err != nil {
		return nil, err
	}
	return newModel(o, func(out **C.sogmm_model, op *C.sogmm_options) C.sogmm_status {
		return C.sogmm_fit_rgbd(out, (*C.uint16_t)(unsafe.SliceData(f.Depth)), (*C.uint8_t)(color), format,
			C.uint32_t(f.Width), C.uint32_t(f.Height), C.double(f.Fx), C.double(f.Fy), C.double(f.Cx),
			C.double(f.Cy), op)
	})
}

// Points returns the points FitRGBD would fit, without fitting: N rows (x, y,
// z, gray) in the camera frame (decimation and depth range from o). A frame
// without a valid pixel gives an empty slice.
func (f Frame) Points(o *Options) ([]float32, error) {
	color, format, err := f.colorArgs()
	if err != nil {
		return nil, err
	}
	op, err := o.raw()
	if err != nil {
		return nil, err
	}
	var n C.size_t
	fill := func(out []float32) error {
		return call(func() C.sogmm_status {
			return C.sogmm_rgbd_to_points_f32(floats(out), C.size_t(len(out)), &n,
				(*C.uint16_t)(unsafe.SliceData(f.Depth)), (*C.uint8_t)(color), format, C.uint32_t(f.Width),
				C.uint32_t(f.Height), C.double(f.Fx), C.double(f.Fy), C.double(f.Cx), C.double(f.Cy), op)
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
