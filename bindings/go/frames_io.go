package sogmm

// #include <stdlib.h>
// #include "sogmm/sogmm.h"
import "C"

import "unsafe"

// The library's frame reader and Redwood .log reader/writer: libsogmm
// decodes the depth PNG and the colour PNG/JPEG itself (libpng,
// libjpeg-turbo with fixed settings), so Go gets the pixels C, Python and
// Rust get from the same files, and the same model from them.

// frameOf copies a C frame's pixels into a Frame (no intrinsics) and frees it.
func frameOf(h *C.sogmm_frame) Frame {
	defer C.sogmm_frame_free(h)
	w, ht := C.sogmm_frame_width(h), C.sogmm_frame_height(h)
	n := int(w) * int(ht)
	f := Frame{Width: uint32(w), Height: uint32(ht),
		Depth: append([]uint16(nil), unsafe.Slice((*uint16)(unsafe.Pointer(C.sogmm_frame_depth(h))), n)...)}
	color := unsafe.Pointer(C.sogmm_frame_color(h))
	switch C.sogmm_frame_color_format(h) {
	case C.SOGMM_COLOR_RGB8:
		f.RGB8 = append([]uint8(nil), unsafe.Slice((*uint8)(color), 3*n)...)
	case C.SOGMM_COLOR_GRAY8:
		f.Gray8 = append([]uint8(nil), unsafe.Slice((*uint8)(color), n)...)
	default: // no colour image: gray 0, what sogmm_fit_frame fits
		f.Gray8 = make([]uint8, n)
	}
	return f
}

// ReadFrame reads a depth PNG (one channel, 16-bit; 8-bit widened) and a
// colour PNG or JPEG ("" = none: Gray8 zeros) into a Frame with Depth and
// RGB8 or Gray8 set. Set Fx, Fy, Cx, Cy before FitRGBD or Map.InsertRGBD.
// Errors (*Error naming the file): ErrIO (cannot read), ErrFormat (corrupt,
// truncated), ErrInvalidData (channels, bit depth, sizes differ), ErrLimit
// (more than 2^26 pixels).
func ReadFrame(depthPath, colorPath string) (Frame, error) {
	if err := abiOnce(); err != nil {
		return Frame{}, err
	}
	d := C.CString(depthPath)
	defer C.free(unsafe.Pointer(d))
	var c *C.char
	if colorPath != "" {
		c = C.CString(colorPath)
		defer C.free(unsafe.Pointer(c))
	}
	var h *C.sogmm_frame
	if err := call(func() C.sogmm_status { return C.sogmm_frame_read(&h, d, c) }); err != nil {
		return Frame{}, err
	}
	return frameOf(h), nil
}

// DecodeFrame is ReadFrame from the files' bytes (color nil = none).
func DecodeFrame(depth, color []byte) (Frame, error) {
	if err := abiOnce(); err != nil {
		return Frame{}, err
	}
	// Go memory without Go pointers may be passed for the call; C copies
	// what it keeps. An empty slice still passes a pointer, so C reports
	// "not a PNG" rather than a NULL argument (as FromBytes).
	var empty byte
	bytesPtr := func(b []byte) unsafe.Pointer {
		if len(b) == 0 {
			return unsafe.Pointer(&empty)
		}
		return unsafe.Pointer(&b[0])
	}
	dp, cp := bytesPtr(depth), unsafe.Pointer(nil)
	if color != nil {
		cp = bytesPtr(color)
	}
	var h *C.sogmm_frame
	if err := call(func() C.sogmm_status {
		return C.sogmm_frame_decode(&h, dp, C.size_t(len(depth)), cp, C.size_t(len(color)))
	}); err != nil {
		return Frame{}, err
	}
	return frameOf(h), nil
}

// Trajectory is a Redwood .log trajectory: Poses[k] (row-major
// camera-to-world rigid transforms, file order) belongs to frame IDs[k], the
// first number of its block's header line.
type Trajectory struct {
	IDs   []int64
	Poses [][16]float64
}

// ReadTrajectory reads a .log file. Errors: ErrIO (cannot read, not a regular
// file), ErrInvalidData naming the file and line (malformed, a pose not rigid).
func ReadTrajectory(path string) (*Trajectory, error) {
	if err := abiOnce(); err != nil {
		return nil, err
	}
	p := C.CString(path)
	defer C.free(unsafe.Pointer(p))
	var h *C.sogmm_trajectory
	if err := call(func() C.sogmm_status { return C.sogmm_trajectory_read(&h, p) }); err != nil {
		return nil, err
	}
	defer C.sogmm_trajectory_free(h)
	n := int(C.sogmm_trajectory_size(h))
	t := &Trajectory{IDs: make([]int64, n), Poses: make([][16]float64, n)}
	copy(t.IDs, unsafe.Slice((*int64)(unsafe.Pointer(C.sogmm_trajectory_ids(h))), n))
	flat := unsafe.Slice((*float64)(unsafe.Pointer(C.sogmm_trajectory_poses(h))), 16*n)
	for k := range t.Poses {
		copy(t.Poses[k][:], flat[16*k:])
	}
	return t, nil
}

// WriteTrajectory writes poses as a .log file (block k with the header
// "k k+1 n"), atomically; read back bitwise. Errors: ErrInvalidArg (no pose,
// a pose not rigid), ErrIO.
func WriteTrajectory(path string, poses [][16]float64) error {
	if err := abiOnce(); err != nil {
		return err
	}
	p := C.CString(path)
	defer C.free(unsafe.Pointer(p))
	var first *C.double
	if len(poses) > 0 {
		first = (*C.double)(unsafe.Pointer(&poses[0][0]))
	}
	return call(func() C.sogmm_status { return C.sogmm_trajectory_write(p, first, C.size_t(len(poses))) })
}
