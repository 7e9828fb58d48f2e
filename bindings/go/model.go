package sogmm

// #include <stdlib.h>
// #include "sogmm/sogmm.h"
import "C"

import (
	"context"
	"fmt"
	"runtime"
	"unsafe"
)

// Model is an owned sogmm_model: a fitted 4-D GMM (x, y, z, gray) with its
// metadata. Arrays come out row-major: weights (M), means (M x 4),
// covariances (M x 4 x 4).
type Model struct {
	ptr *C.sogmm_model
}

// finalizerRuns counts handles freed by the finalizer (for the tests).
var finalizerRuns atomicCounter

// newModel runs a C constructor with o's handle (nil o = defaults) and wraps
// the model it creates.
func newModel(o *Options, f func(out **C.sogmm_model, op *C.sogmm_options) C.sogmm_status) (*Model, error) {
	if err := abiOnce(); err != nil {
		return nil, err
	}
	m := &Model{}
	if err := callWith(o, func(op *C.sogmm_options) C.sogmm_status { return f(&m.ptr, op) }); err != nil {
		return nil, err
	}
	runtime.SetFinalizer(m, func(m *Model) {
		finalizerRuns.add()
		m.Close()
	})
	return m, nil
}

// do runs one C call on m's handle and o's (nil o = defaults), keeping both
// alive until it returns; a closed handle gives ErrClosed.
func (m *Model) do(o *Options, f func(p *C.sogmm_model, op *C.sogmm_options) C.sogmm_status) error {
	if m == nil || m.ptr == nil {
		return ErrClosed
	}
	defer runtime.KeepAlive(m)
	return callWith(o, func(op *C.sogmm_options) C.sogmm_status { return f(m.ptr, op) })
}

// derive creates a new model from m (clone, merge, transform).
func (m *Model) derive(f func(out **C.sogmm_model, p *C.sogmm_model) C.sogmm_status) (*Model, error) {
	if m == nil || m.ptr == nil {
		return nil, ErrClosed
	}
	defer runtime.KeepAlive(m)
	return newModel(nil, func(out **C.sogmm_model, _ *C.sogmm_options) C.sogmm_status { return f(out, m.ptr) })
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

// Fit fits a model to n points: points holds n rows (x, y, z, gray). o may
// be nil (defaults; OptNComponents fixes K). ctx cancels: the call stops
// within about 50 ms once ctx is done (the error then satisfies
// errors.Is(err, ErrCancelled) and errors.Is(err, ctx.Err())); the progress
// func of o (OnProgress) gets the reports.
func Fit(ctx context.Context, points []float32, o *Options) (*Model, error) {
	n, err := rowsOf(points, 4, "points")
	if err != nil {
		return nil, err
	}
	return withProgress(ctx, o, func(o *Options) (*Model, error) {
		return newModel(o, func(out **C.sogmm_model, op *C.sogmm_options) C.sogmm_status {
			return C.sogmm_fit_points_f32(out, floats(points), C.size_t(n), nil, op)
		})
	})
}

// FromArrays builds a model from M weights, M x 4 means and M x 4 x 4
// covariances (copied); supportSize = points it stands for (0 = unknown).
func FromArrays(weights, means, covariances []float32, supportSize uint64) (*Model, error) {
	m := len(weights)
	if len(means) != 4*m || len(covariances) != 16*m {
		return nil, invalidArg("%d weights need %d means and %d covariance floats, got %d and %d",
			m, 4*m, 16*m, len(means), len(covariances))
	}
	return newModel(nil, func(out **C.sogmm_model, _ *C.sogmm_options) C.sogmm_status {
		return C.sogmm_model_from_arrays_f32(out, C.size_t(m), floats(weights), floats(means), floats(covariances),
			C.uint64_t(supportSize))
	})
}

// Load reads a .sogmm file (read keys of o apply; o may be nil).
func Load(path string, o *Options) (*Model, error) {
	p := C.CString(path)
	defer C.free(unsafe.Pointer(p))
	return newModel(o, func(out **C.sogmm_model, op *C.sogmm_options) C.sogmm_status {
		return C.sogmm_model_load(out, p, op)
	})
}

// FromBytes reads a model from the bytes of a .sogmm file.
func FromBytes(data []byte, o *Options) (*Model, error) {
	// An empty slice may have a nil data pointer; C would then report a NULL
	// argument instead of "size 0 is not a .sogmm document" (SOGMM_E_FORMAT).
	var empty byte
	ptr := unsafe.Pointer(&empty)
	if len(data) > 0 {
		ptr = unsafe.Pointer(&data[0])
	}
	return newModel(o, func(out **C.sogmm_model, op *C.sogmm_options) C.sogmm_status {
		return C.sogmm_model_load_from_memory(out, ptr, C.size_t(len(data)), op)
	})
}

// Clone is a deep copy including metadata.
func (m *Model) Clone() (*Model, error) {
	return m.derive(func(out **C.sogmm_model, p *C.sogmm_model) C.sogmm_status { return C.sogmm_model_clone(out, p) })
}

// Merge returns a new model with the components of m and other, weighted by
// support size.
func (m *Model) Merge(other *Model) (*Model, error) {
	if other == nil || other.ptr == nil {
		return nil, ErrClosed
	}
	defer runtime.KeepAlive(other)
	return m.derive(func(out **C.sogmm_model, p *C.sogmm_model) C.sogmm_status {
		return C.sogmm_model_merge(out, p, other.ptr)
	})
}

// Transform returns a new model moved by a rigid row-major 4 x 4 transform.
func (m *Model) Transform(pose [16]float64) (*Model, error) {
	return m.derive(func(out **C.sogmm_model, p *C.sogmm_model) C.sogmm_status {
		return C.sogmm_model_transform(out, p, (*C.double)(&pose[0]))
	})
}

// Save writes a .sogmm file atomically (write keys of o apply; o may be nil).
func (m *Model) Save(path string, o *Options) error {
	cp := C.CString(path)
	defer C.free(unsafe.Pointer(cp))
	return m.do(o, func(p *C.sogmm_model, op *C.sogmm_options) C.sogmm_status { return C.sogmm_model_save(p, cp, op) })
}

// Bytes returns the bytes of a .sogmm file.
func (m *Model) Bytes(o *Options) ([]byte, error) {
	var buf *C.sogmm_buffer
	err := m.do(o, func(p *C.sogmm_model, op *C.sogmm_options) C.sogmm_status {
		return C.sogmm_model_save_to_memory(&buf, p, op)
	})
	if err != nil {
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
