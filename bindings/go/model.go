package sogmm

// #include <stdlib.h>
// #include "sogmm/sogmm.h"
import "C"

import (
	"fmt"
	"math"
	"runtime"
	"unsafe"
)

// Information keys of a model (SOGMM_INFO_*); read with InfoF64 / InfoI64.
const (
	InfoSupportSize    Key = C.SOGMM_INFO_SUPPORT_SIZE
	InfoCreatedUnixMs  Key = C.SOGMM_INFO_CREATED_UNIX_MS
	InfoFitIterations  Key = C.SOGMM_INFO_FIT_ITERATIONS
	InfoFitConverged   Key = C.SOGMM_INFO_FIT_CONVERGED
	InfoFitLogLik      Key = C.SOGMM_INFO_FIT_LOG_LIKELIHOOD
	InfoFitBandwidth   Key = C.SOGMM_INFO_FIT_BANDWIDTH
	InfoFitSeed        Key = C.SOGMM_INFO_FIT_SEED
	InfoFitNPoints     Key = C.SOGMM_INFO_FIT_N_POINTS
	InfoFitSecondsTot  Key = C.SOGMM_INFO_FIT_SECONDS_TOTAL
	InfoCameraWidth    Key = C.SOGMM_INFO_CAMERA_WIDTH
	InfoCameraHeight   Key = C.SOGMM_INFO_CAMERA_HEIGHT
	InfoCameraDecimate Key = C.SOGMM_INFO_CAMERA_DECIMATION
)

// Model is an owned sogmm_model: a fitted 4-D GMM (x, y, z, gray) with its
// metadata. Arrays come out row-major: weights (M), means (M x 4),
// covariances (M x 4 x 4).
type Model struct {
	ptr *C.sogmm_model
}

// finalizerRuns counts handles freed by the finalizer (for the tests).
var finalizerRuns atomicCounter

func newModel(f func(out **C.sogmm_model) C.sogmm_status) (*Model, error) {
	if err := abiOnce(); err != nil {
		return nil, err
	}
	m := &Model{}
	if err := call(func() C.sogmm_status { return f(&m.ptr) }); err != nil {
		return nil, err
	}
	runtime.SetFinalizer(m, func(m *Model) {
		finalizerRuns.add()
		m.Close()
	})
	return m, nil
}

// Close frees the model. It is idempotent; it must not race with other calls
// on m. The finalizer only backs up a forgotten Close.
func (m *Model) Close() {
	if m == nil || m.ptr == nil {
		return
	}
	runtime.SetFinalizer(m, nil)
	C.sogmm_model_free(m.ptr)
	m.ptr = nil
}

func (m *Model) raw() (*C.sogmm_model, error) {
	if m == nil || m.ptr == nil {
		return nil, ErrClosed
	}
	return m.ptr, nil
}

// floats returns a pointer to the first element, or nil for an empty slice
// (&s[0] would panic). Float slices hold no Go pointers, so passing them to C
// is allowed, and C does not keep them after the call.
func floats(s []float32) *C.float {
	if len(s) == 0 {
		return nil
	}
	return (*C.float)(unsafe.Pointer(&s[0]))
}

func rowsOf(data []float32, cols int, what string) (int, error) {
	if len(data)%cols != 0 {
		return 0, invalidArg("%s has %d floats, not a multiple of %d", what, len(data), cols)
	}
	return len(data) / cols, nil
}

func optionsPtr(o *Options) (*C.sogmm_options, error) { return o.raw() }

// Fit fits a model to n points: points holds n rows (x, y, z, gray). o may be nil.
func Fit(points []float32, o *Options) (*Model, error) {
	n, err := rowsOf(points, 4, "points")
	if err != nil {
		return nil, err
	}
	op, err := optionsPtr(o)
	if err != nil {
		return nil, err
	}
	defer runtime.KeepAlive(o)
	return newModel(func(out **C.sogmm_model) C.sogmm_status {
		return C.sogmm_fit_points_f32(out, floats(points), C.size_t(n), op)
	})
}

// FitFixedK fits exactly k components (1 <= k <= n).
func FitFixedK(points []float32, k int, o *Options) (*Model, error) {
	n, err := rowsOf(points, 4, "points")
	if err != nil {
		return nil, err
	}
	if k < 0 {
		return nil, invalidArg("k must be >= 1, got %d", k)
	}
	op, err := optionsPtr(o)
	if err != nil {
		return nil, err
	}
	defer runtime.KeepAlive(o)
	return newModel(func(out **C.sogmm_model) C.sogmm_status {
		return C.sogmm_fit_points_fixed_k_f32(out, floats(points), C.size_t(n), C.size_t(k), op)
	})
}

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
	op, err := optionsPtr(o)
	if err != nil {
		return nil, err
	}
	defer runtime.KeepAlive(o)
	return newModel(func(out **C.sogmm_model) C.sogmm_status {
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
	op, err := optionsPtr(o)
	if err != nil {
		return nil, err
	}
	defer runtime.KeepAlive(o)
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
	if err := fill(out); err != nil {
		return nil, err
	}
	return out, nil
}

// FromArrays builds a model from M weights, M x 4 means and M x 4 x 4
// covariances (copied); supportSize = points it stands for (0 = unknown).
func FromArrays(weights, means, covariances []float32, supportSize uint64) (*Model, error) {
	m := len(weights)
	if len(means) != 4*m || len(covariances) != 16*m {
		return nil, invalidArg("%d weights need %d means and %d covariance floats, got %d and %d",
			m, 4*m, 16*m, len(means), len(covariances))
	}
	return newModel(func(out **C.sogmm_model) C.sogmm_status {
		return C.sogmm_model_from_arrays_f32(out, C.size_t(m), floats(weights), floats(means), floats(covariances),
			C.uint64_t(supportSize))
	})
}

// Load reads a .sogmm file (read keys of o apply; o may be nil).
func Load(path string, o *Options) (*Model, error) {
	op, err := optionsPtr(o)
	if err != nil {
		return nil, err
	}
	defer runtime.KeepAlive(o)
	p := C.CString(path)
	defer C.free(unsafe.Pointer(p))
	return newModel(func(out **C.sogmm_model) C.sogmm_status { return C.sogmm_model_load(out, p, op) })
}

// FromBytes reads a model from the bytes of a .sogmm file.
func FromBytes(data []byte, o *Options) (*Model, error) {
	op, err := optionsPtr(o)
	if err != nil {
		return nil, err
	}
	defer runtime.KeepAlive(o)
	// An empty slice may have a nil data pointer; C would then report a NULL
	// argument instead of "size 0 is not a .sogmm document" (SOGMM_E_FORMAT).
	var empty byte
	ptr := unsafe.Pointer(&empty)
	if len(data) > 0 {
		ptr = unsafe.Pointer(&data[0])
	}
	return newModel(func(out **C.sogmm_model) C.sogmm_status {
		return C.sogmm_model_load_from_memory(out, ptr, C.size_t(len(data)), op)
	})
}

// Clone is a deep copy including metadata.
func (m *Model) Clone() (*Model, error) {
	p, err := m.raw()
	if err != nil {
		return nil, err
	}
	defer runtime.KeepAlive(m)
	return newModel(func(out **C.sogmm_model) C.sogmm_status { return C.sogmm_model_clone(out, p) })
}

// NComponents is M (>= 1).
func (m *Model) NComponents() (int, error) {
	p, err := m.raw()
	if err != nil {
		return 0, err
	}
	defer runtime.KeepAlive(m)
	var n C.size_t
	err = call(func() C.sogmm_status { return C.sogmm_model_n_components(p, &n) })
	return int(n), err
}

func (m *Model) array(per int, get func(*C.sogmm_model, *C.float, C.size_t) C.sogmm_status) ([]float32, error) {
	n, err := m.NComponents()
	if err != nil {
		return nil, err
	}
	defer runtime.KeepAlive(m)
	out := make([]float32, n*per)
	if err := call(func() C.sogmm_status { return get(m.ptr, floats(out), C.size_t(len(out))) }); err != nil {
		return nil, err
	}
	return out, nil
}

// Weights are the M component weights.
func (m *Model) Weights() ([]float32, error) {
	return m.array(1, func(p *C.sogmm_model, o *C.float, c C.size_t) C.sogmm_status {
		return C.sogmm_model_get_weights_f32(p, o, c)
	})
}

// Means are M rows of (x, y, z, gray).
func (m *Model) Means() ([]float32, error) {
	return m.array(4, func(p *C.sogmm_model, o *C.float, c C.size_t) C.sogmm_status {
		return C.sogmm_model_get_means_f32(p, o, c)
	})
}

// Covariances are M row-major 4 x 4 matrices.
func (m *Model) Covariances() ([]float32, error) {
	return m.array(16, func(p *C.sogmm_model, o *C.float, c C.size_t) C.sogmm_status {
		return C.sogmm_model_get_covariances_f32(p, o, c)
	})
}

// InfoF64 reads an f64 information key; errors.Is(err, ErrNotFound) when the
// model does not have it.
func (m *Model) InfoF64(key Key) (float64, error) {
	p, err := m.raw()
	if err != nil {
		return 0, err
	}
	defer runtime.KeepAlive(m)
	var v C.double
	err = call(func() C.sogmm_status { return C.sogmm_model_get_info_f64(p, C.sogmm_key(key), &v) })
	return float64(v), err
}

// InfoI64 reads an i64 information key (see InfoF64).
func (m *Model) InfoI64(key Key) (int64, error) {
	p, err := m.raw()
	if err != nil {
		return 0, err
	}
	defer runtime.KeepAlive(m)
	var v C.int64_t
	err = call(func() C.sogmm_status { return C.sogmm_model_get_info_i64(p, C.sogmm_key(key), &v) })
	return int64(v), err
}

// Pose is the row-major 4 x 4 pose of the model's frame (ErrNotFound if unset).
func (m *Model) Pose() ([16]float64, error) {
	var pose [16]float64
	p, err := m.raw()
	if err != nil {
		return pose, err
	}
	defer runtime.KeepAlive(m)
	err = call(func() C.sogmm_status { return C.sogmm_model_get_pose(p, (*C.double)(&pose[0])) })
	return pose, err
}

// SetPose sets the pose (a finite rigid transform). Needs exclusive use of m.
func (m *Model) SetPose(pose [16]float64) error {
	p, err := m.raw()
	if err != nil {
		return err
	}
	defer runtime.KeepAlive(m)
	return call(func() C.sogmm_status { return C.sogmm_model_set_pose(p, (*C.double)(&pose[0])) })
}

// ClearPose removes the pose. Needs exclusive use of m.
func (m *Model) ClearPose() error {
	p, err := m.raw()
	if err != nil {
		return err
	}
	defer runtime.KeepAlive(m)
	return call(func() C.sogmm_status { return C.sogmm_model_clear_pose(p) })
}

// Value of a metadata key (its first pair); ErrNotFound if absent.
func (m *Model) Value(key string) (string, error) {
	p, err := m.raw()
	if err != nil {
		return "", err
	}
	defer runtime.KeepAlive(m)
	k := C.CString(key)
	defer C.free(unsafe.Pointer(k))
	var v *C.char
	var s string
	err = call(func() C.sogmm_status {
		st := C.sogmm_model_get_value(p, k, &v)
		if st == C.SOGMM_OK {
			s = C.GoString(v) // copied before any other call can invalidate it
		}
		return st
	})
	return s, err
}

// SetValue adds a pair or replaces the first pair's value. Needs exclusive use of m.
func (m *Model) SetValue(key, value string) error {
	p, err := m.raw()
	if err != nil {
		return err
	}
	defer runtime.KeepAlive(m)
	k, v := C.CString(key), C.CString(value)
	defer C.free(unsafe.Pointer(k))
	defer C.free(unsafe.Pointer(v))
	return call(func() C.sogmm_status { return C.sogmm_model_set_value(p, k, v) })
}

// Values lists every metadata pair in order.
func (m *Model) Values() ([][2]string, error) {
	p, err := m.raw()
	if err != nil {
		return nil, err
	}
	defer runtime.KeepAlive(m)
	var n C.size_t
	if err := call(func() C.sogmm_status { return C.sogmm_model_value_count(p, &n) }); err != nil {
		return nil, err
	}
	out := make([][2]string, 0, int(n))
	for i := C.size_t(0); i < n; i++ {
		var k, v *C.char
		if err := call(func() C.sogmm_status { return C.sogmm_model_value_at(p, i, &k, &v) }); err != nil {
			return nil, err
		}
		out = append(out, [2]string{C.GoString(k), C.GoString(v)})
	}
	return out, nil
}

// Sample draws n points as n rows of dims floats (4: x, y, z, gray; 3: x, y,
// z), grouped by component. Same seed, same samples. o (may be nil) gives
// the truncation.
func (m *Model) Sample(n int, seed uint64, dims int, o *Options) ([]float32, error) {
	if dims != 3 && dims != 4 {
		return nil, invalidArg("dims must be 3 or 4, got %d", dims)
	}
	if n < 0 {
		return nil, invalidArg("n must be >= 0, got %d", n)
	}
	if n > math.MaxInt/dims {
		return nil, &Error{Status: ErrLimit, Message: fmt.Sprintf("%d samples of %d floats overflow int", n, dims)}
	}
	p, err := m.raw()
	if err != nil {
		return nil, err
	}
	op, err := optionsPtr(o)
	if err != nil {
		return nil, err
	}
	defer runtime.KeepAlive(m)
	defer runtime.KeepAlive(o)
	out := make([]float32, n*dims)
	err = call(func() C.sogmm_status {
		return C.sogmm_model_sample_f32(p, C.size_t(n), C.uint64_t(seed), C.int32_t(dims), op, floats(out))
	})
	if err != nil {
		return nil, err
	}
	return out, nil
}

// RegressGray gives the expected gray and its conditional variance at n
// points (xyz: n rows of 3).
func (m *Model) RegressGray(xyz []float32) (mean, variance []float32, err error) {
	n, err := rowsOf(xyz, 3, "xyz")
	if err != nil {
		return nil, nil, err
	}
	p, err := m.raw()
	if err != nil {
		return nil, nil, err
	}
	defer runtime.KeepAlive(m)
	mean, variance = make([]float32, n), make([]float32, n)
	err = call(func() C.sogmm_status {
		return C.sogmm_model_regress_gray_f32(p, floats(xyz), C.size_t(n), floats(mean), floats(variance))
	})
	if err != nil {
		return nil, nil, err
	}
	return mean, variance, nil
}

// ScoreSamples is the log-density of rows of dims floats (4: joint; 3:
// marginal over gray).
func (m *Model) ScoreSamples(points []float32, dims int) ([]float64, error) {
	if dims != 3 && dims != 4 {
		return nil, invalidArg("dims must be 3 or 4, got %d", dims)
	}
	n, err := rowsOf(points, dims, "points")
	if err != nil {
		return nil, err
	}
	p, err := m.raw()
	if err != nil {
		return nil, err
	}
	defer runtime.KeepAlive(m)
	out := make([]float64, n)
	var o *C.double
	if n > 0 {
		o = (*C.double)(&out[0])
	}
	err = call(func() C.sogmm_status {
		return C.sogmm_model_score_samples_f32(p, floats(points), C.size_t(n), C.int32_t(dims), o)
	})
	if err != nil {
		return nil, err
	}
	return out, nil
}

// Merge returns a new model with the components of m and other, weighted by
// support size.
func (m *Model) Merge(other *Model) (*Model, error) {
	a, err := m.raw()
	if err != nil {
		return nil, err
	}
	b, err := other.raw()
	if err != nil {
		return nil, err
	}
	defer runtime.KeepAlive(m)
	defer runtime.KeepAlive(other)
	return newModel(func(out **C.sogmm_model) C.sogmm_status { return C.sogmm_model_merge(out, a, b) })
}

// Transform returns a new model moved by a rigid row-major 4 x 4 transform.
func (m *Model) Transform(pose [16]float64) (*Model, error) {
	p, err := m.raw()
	if err != nil {
		return nil, err
	}
	defer runtime.KeepAlive(m)
	return newModel(func(out **C.sogmm_model) C.sogmm_status {
		return C.sogmm_model_transform(out, p, (*C.double)(&pose[0]))
	})
}

// Save writes a .sogmm file atomically (write keys of o apply; o may be nil).
func (m *Model) Save(path string, o *Options) error {
	p, err := m.raw()
	if err != nil {
		return err
	}
	op, err := optionsPtr(o)
	if err != nil {
		return err
	}
	defer runtime.KeepAlive(m)
	defer runtime.KeepAlive(o)
	cp := C.CString(path)
	defer C.free(unsafe.Pointer(cp))
	return call(func() C.sogmm_status { return C.sogmm_model_save(p, cp, op) })
}

// Bytes returns the bytes of a .sogmm file.
func (m *Model) Bytes(o *Options) ([]byte, error) {
	p, err := m.raw()
	if err != nil {
		return nil, err
	}
	op, err := optionsPtr(o)
	if err != nil {
		return nil, err
	}
	defer runtime.KeepAlive(m)
	defer runtime.KeepAlive(o)
	var buf *C.sogmm_buffer
	if err := call(func() C.sogmm_status { return C.sogmm_model_save_to_memory(&buf, p, op) }); err != nil {
		return nil, err
	}
	defer C.sogmm_buffer_free(buf)
	// Copied out of the library's buffer (size_t: no C.int truncation).
	data := unsafe.Slice((*byte)(unsafe.Pointer(C.sogmm_buffer_data(buf))), int(C.sogmm_buffer_size(buf)))
	return append([]byte(nil), data...), nil
}

// String describes the handle.
func (m *Model) String() string {
	n, err := m.NComponents()
	if err != nil {
		return "sogmm.Model(closed)"
	}
	return fmt.Sprintf("sogmm.Model(%d components)", n)
}
