package sogmm

// #include <stdlib.h>
// #include "sogmm/sogmm.h"
import "C"

import (
	"fmt"
	"math"
	"unsafe"
)

// NComponents is M (>= 1).
func (m *Model) NComponents() (int, error) {
	var n C.size_t
	err := m.do(nil, func(p *C.sogmm_model, _ *C.sogmm_options) C.sogmm_status {
		return C.sogmm_model_n_components(p, &n)
	})
	return int(n), err
}

func (m *Model) array(per int, get func(*C.sogmm_model, *C.float, C.size_t) C.sogmm_status) ([]float32, error) {
	n, err := m.NComponents()
	if err != nil {
		return nil, err
	}
	out := make([]float32, n*per)
	err = m.do(nil, func(p *C.sogmm_model, _ *C.sogmm_options) C.sogmm_status {
		return get(p, floats(out), C.size_t(len(out)))
	})
	if err != nil {
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
	var v C.double
	err := m.do(nil, func(p *C.sogmm_model, _ *C.sogmm_options) C.sogmm_status {
		return C.sogmm_model_get_info_f64(p, C.sogmm_key(key), &v)
	})
	return float64(v), err
}

// InfoI64 reads an i64 information key (see InfoF64).
func (m *Model) InfoI64(key Key) (int64, error) {
	var v C.int64_t
	err := m.do(nil, func(p *C.sogmm_model, _ *C.sogmm_options) C.sogmm_status {
		return C.sogmm_model_get_info_i64(p, C.sogmm_key(key), &v)
	})
	return int64(v), err
}

// Pose is the row-major 4 x 4 pose of the model's frame (ErrNotFound if unset).
func (m *Model) Pose() ([16]float64, error) {
	var pose [16]float64
	err := m.do(nil, func(p *C.sogmm_model, _ *C.sogmm_options) C.sogmm_status {
		return C.sogmm_model_get_pose(p, (*C.double)(&pose[0]))
	})
	return pose, err
}

// SetPose sets the pose (a finite rigid transform). Needs exclusive use of m.
func (m *Model) SetPose(pose [16]float64) error {
	return m.do(nil, func(p *C.sogmm_model, _ *C.sogmm_options) C.sogmm_status {
		return C.sogmm_model_set_pose(p, (*C.double)(&pose[0]))
	})
}

// ClearPose removes the pose. Needs exclusive use of m.
func (m *Model) ClearPose() error {
	return m.do(nil, func(p *C.sogmm_model, _ *C.sogmm_options) C.sogmm_status { return C.sogmm_model_clear_pose(p) })
}

// Value of a metadata key (its first pair); ErrNotFound if absent.
func (m *Model) Value(key string) (string, error) {
	k := C.CString(key)
	defer C.free(unsafe.Pointer(k))
	var s string
	err := m.do(nil, func(p *C.sogmm_model, _ *C.sogmm_options) C.sogmm_status {
		var v *C.char
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
	k, v := C.CString(key), C.CString(value)
	defer C.free(unsafe.Pointer(k))
	defer C.free(unsafe.Pointer(v))
	return m.do(nil, func(p *C.sogmm_model, _ *C.sogmm_options) C.sogmm_status {
		return C.sogmm_model_set_value(p, k, v)
	})
}

// Values lists every metadata pair in order.
func (m *Model) Values() ([][2]string, error) {
	var out [][2]string
	err := m.do(nil, func(p *C.sogmm_model, _ *C.sogmm_options) C.sogmm_status {
		var n C.size_t
		if st := C.sogmm_model_value_count(p, &n); st != C.SOGMM_OK {
			return st
		}
		for i := C.size_t(0); i < n; i++ {
			var k, v *C.char
			if st := C.sogmm_model_value_at(p, i, &k, &v); st != C.SOGMM_OK {
				return st
			}
			out = append(out, [2]string{C.GoString(k), C.GoString(v)})
		}
		return C.SOGMM_OK
	})
	return out, err
}

func checkDims(dims int) error {
	if dims != 3 && dims != 4 {
		return invalidArg("dims must be 3 or 4, got %d", dims)
	}
	return nil
}

// scoreBuffer checks a score request (rows of dims floats) and allocates its
// n doubles.
func scoreBuffer(points []float32, dims int) (int, []float64, error) {
	if err := checkDims(dims); err != nil {
		return 0, nil, err
	}
	n, err := rowsOf(points, dims, "points")
	if err != nil {
		return 0, nil, err
	}
	return n, make([]float64, n), nil
}

// doubles is floats for a float64 slice (nil when empty).
func doubles(s []float64) *C.double {
	if len(s) == 0 {
		return nil
	}
	return (*C.double)(&s[0])
}

// sampleBuffer checks a sample request and allocates its n * dims floats.
func sampleBuffer(n, dims int) ([]float32, error) {
	if err := checkDims(dims); err != nil {
		return nil, err
	}
	if n < 0 {
		return nil, invalidArg("n must be >= 0, got %d", n)
	}
	if n > math.MaxInt/dims {
		return nil, &Error{Status: ErrLimit, Message: fmt.Sprintf("%d samples of %d floats overflow int", n, dims)}
	}
	return make([]float32, n*dims), nil
}
