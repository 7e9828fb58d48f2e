package sogmm

// #include <stdlib.h>
// #include "sogmm/sogmm.h"
import "C"

import (
	"context"
	"runtime"
	"unsafe"
)

// The values of OptMapFusionMethod (a map's keys are OptMap*; a map also
// uses the fit and RGB-D keys).
const (
	FusionHellinger = C.SOGMM_FUSION_HELLINGER
	FusionKL        = C.SOGMM_FUSION_KL
)

// Map is an owned sogmm_map: an incremental world map that fits only the
// parts of each posed frame it does not yet explain (core/include/sogmm/map.hpp).
// Poses are row-major 4 x 4 camera-to-world rigid transforms. Inserts,
// flushes and Close need exclusive use; the queries (Stats, FrameStats,
// Export, ScoreSamples, RegressGray, Sample, Save) only read the map and may
// run concurrently with each other. A call that breaks this rule, from
// another goroutine or from the progress func of a call on the same map,
// returns an error with ErrBusy ("map busy: ...") and changes nothing; Close
// then leaves the map open (close it after that call returns).
type Map struct {
	ptr      *C.sogmm_map
	guard    mapGuard
	progress ProgressFunc // of the options the map was created with (OnProgress)
}

// MapStats are the totals of a map.
type MapStats struct {
	Components, Pending, Frames, Flushes, Fused uint64
	Refits                                      uint64 // revisit refits run (also counted in Flushes)
}

// MapFrameStats is what one insert did.
type MapFrameStats struct {
	Points, Novel, Components uint64 // Components: map size after the insert
	Flushed                   bool
	MsNovelty, MsFit, MsMerge float64
	Replaced                  uint64 // components this insert's revisit refit replaced (0: none ran)
	Pose                      [16]float64
}

func wrapMap(o *Options, f func(out **C.sogmm_map, op *C.sogmm_options) C.sogmm_status) (*Map, error) {
	if err := abiOnce(); err != nil {
		return nil, err
	}
	m := &Map{}
	if o != nil {
		m.progress = o.progress
	}
	// The handle comes out in a local: cgo refuses a pointer into a struct
	// that holds Go pointers (the progress func).
	var ptr *C.sogmm_map
	if err := callWith(o, func(op *C.sogmm_options) C.sogmm_status { return f(&ptr, op) }); err != nil {
		return nil, err
	}
	m.ptr = ptr
	runtime.SetFinalizer(m, (*Map).Close)
	return m, nil
}

// NewMap creates an empty map with the map, fit and RGB-D keys of o (nil =
// defaults) and its progress func (OnProgress), to which the map's inserts
// and flushes report.
func NewMap(o *Options) (*Map, error) {
	return wrapMap(o, func(out **C.sogmm_map, op *C.sogmm_options) C.sogmm_status { return C.sogmm_map_create(out, op) })
}

// LoadMap reads a map file (or any world-frame model); o's keys and progress
// func govern later inserts.
func LoadMap(path string, o *Options) (*Map, error) {
	cp := C.CString(path)
	defer C.free(unsafe.Pointer(cp))
	return wrapMap(o, func(out **C.sogmm_map, op *C.sogmm_options) C.sogmm_status { return C.sogmm_map_load(out, cp, op) })
}

// Close frees the map; idempotent. While another call uses the map (on
// another goroutine, or from that call's progress func) it does nothing: the
// map stays open and usable (ErrBusy rule of Map).
func (m *Map) Close() {
	if m == nil || m.guard.take(true, "Close") != nil {
		return
	}
	defer m.guard.release(true)
	if m.ptr == nil {
		return
	}
	runtime.SetFinalizer(m, nil)
	C.sogmm_map_free(m.ptr)
	m.ptr = nil
}

func (m *Map) do(f func(p *C.sogmm_map) C.sogmm_status) error {
	return m.doWith(nil, func(p *C.sogmm_map, _ *C.sogmm_options) C.sogmm_status { return f(p) })
}

// doWith runs one C call on m's handle and o's (nil o = defaults), keeping
// both alive until it returns.
func (m *Map) doWith(o *Options, f func(p *C.sogmm_map, op *C.sogmm_options) C.sogmm_status) error {
	if m == nil || m.ptr == nil {
		return ErrClosed
	}
	defer runtime.KeepAlive(m)
	return callWith(o, func(op *C.sogmm_options) C.sogmm_status { return f(m.ptr, op) })
}

// InsertPoints inserts N rows (x, y, z, gray) in the camera frame with the
// frame's camera-to-world pose. ctx cancels the fit the insert may run (as
// Fit), which the progress func of the map's options (OnProgress) reports; a
// cancelled or failed insert leaves the map as it was.
func (m *Map) InsertPoints(ctx context.Context, points []float32, pose [16]float64) error {
	n, err := rowsOf(points, 4, "points")
	if err != nil {
		return err
	}
	if n == 0 { // C sees a nil slice as a NULL pointer; the problem is the empty frame
		return &Error{Status: ErrInvalidData, Message: "points: an empty frame (no point)"}
	}
	return m.change(ctx, "InsertPoints", func(p *C.sogmm_map) C.sogmm_status {
		return C.sogmm_map_insert_points_f32(p, floats(points), C.size_t(n), (*C.double)(&pose[0]))
	})
}

// InsertRGBD inserts an RGB-D frame (decimation and depth range from the
// options the map was created with) with its camera-to-world pose; ctx and
// progress as InsertPoints.
func (m *Map) InsertRGBD(ctx context.Context, f Frame, pose [16]float64) error {
	h, err := f.handle()
	if err != nil {
		return err
	}
	defer C.sogmm_frame_free(h)
	return m.change(ctx, "InsertRGBD", func(p *C.sogmm_map) C.sogmm_status {
		return C.sogmm_map_insert_frame(p, h, (*C.double)(&pose[0]))
	})
}

// Flush fits the pending novel points now; ctx and progress as InsertPoints
// (a cancelled flush keeps the pending points).
func (m *Map) Flush(ctx context.Context) error {
	return m.change(ctx, "Flush", func(p *C.sogmm_map) C.sogmm_status { return C.sogmm_map_flush(p) })
}

// DiscardPending drops the points pending for a fit (they never become
// components) and returns how many there were. The frames stay recorded. The
// way out when a flush keeps failing and the map cannot be saved.
func (m *Map) DiscardPending() (uint64, error) {
	var dropped C.uint64_t
	err := m.change(context.Background(), "DiscardPending", func(p *C.sogmm_map) C.sogmm_status {
		return C.sogmm_map_discard_pending(p, &dropped)
	})
	return uint64(dropped), err
}

// Stats returns the map's totals (read key by key, sogmm_map_get_i64).
func (m *Map) Stats() (MapStats, error) {
	var s MapStats
	fields := []struct {
		key C.sogmm_key
		dst *uint64
	}{{C.SOGMM_MAP_N_COMPONENTS, &s.Components}, {C.SOGMM_MAP_N_PENDING, &s.Pending},
		{C.SOGMM_MAP_N_FRAMES, &s.Frames}, {C.SOGMM_MAP_N_FLUSHES, &s.Flushes}, {C.SOGMM_MAP_N_FUSED, &s.Fused},
		{C.SOGMM_MAP_N_REFITS, &s.Refits}}
	err := m.read("Stats", func() error {
		return m.do(func(p *C.sogmm_map) C.sogmm_status {
			for _, f := range fields {
				var v C.int64_t
				if st := C.sogmm_map_get_i64(p, f.key, &v); st != C.SOGMM_OK {
					return st
				}
				*f.dst = uint64(v)
			}
			return C.SOGMM_OK
		})
	})
	return s, err
}

// Origin returns the map's origin (anchor; world x, y, z in metres): the map
// holds its components relative to it, so that far from the world origin
// (geo-referenced poses) they keep room-scale resolution. By default the first
// frame's translation rounded to 1 km per axis (0 near the world origin); a
// loaded map's comes from its file (sogmm_map_get_origin).
func (m *Map) Origin() ([3]float64, error) {
	var o [3]C.double
	err := m.read("Origin", func() error {
		return m.do(func(p *C.sogmm_map) C.sogmm_status { return C.sogmm_map_get_origin(p, &o[0]) })
	})
	return [3]float64{float64(o[0]), float64(o[1]), float64(o[2])}, err
}

// SetOrigin declares the origin (finite, within float32 range) instead of the
// first frame's; only before the first insert, else an error with
// StatusInvalidArg (sogmm_map_set_origin).
func (m *Map) SetOrigin(origin [3]float64) error {
	o := [3]C.double{C.double(origin[0]), C.double(origin[1]), C.double(origin[2])}
	return m.change(context.Background(), "SetOrigin", func(p *C.sogmm_map) C.sogmm_status { return C.sogmm_map_set_origin(p, &o[0]) })
}

// FrameStats returns what the insert of frame i (insertion order) did (read
// key by key, sogmm_map_frame_get_*).
func (m *Map) FrameStats(i uint64) (MapFrameStats, error) {
	var out MapFrameStats
	var flushed uint64
	ints := []struct {
		key C.sogmm_key
		dst *uint64
	}{{C.SOGMM_MAP_FRAME_N_POINTS, &out.Points}, {C.SOGMM_MAP_FRAME_N_NOVEL, &out.Novel},
		{C.SOGMM_MAP_FRAME_N_COMPONENTS, &out.Components}, {C.SOGMM_MAP_FRAME_FLUSHED, &flushed},
		{C.SOGMM_MAP_FRAME_N_REPLACED, &out.Replaced}}
	floats := []struct {
		key C.sogmm_key
		dst *float64
	}{{C.SOGMM_MAP_FRAME_MS_NOVELTY, &out.MsNovelty}, {C.SOGMM_MAP_FRAME_MS_FIT, &out.MsFit},
		{C.SOGMM_MAP_FRAME_MS_MERGE, &out.MsMerge}}
	var pose [16]C.double
	err := m.read("FrameStats", func() error {
		return m.do(func(p *C.sogmm_map) C.sogmm_status {
			frame := C.uint64_t(i)
			for _, f := range ints {
				var v C.int64_t
				if st := C.sogmm_map_frame_get_i64(p, frame, f.key, &v); st != C.SOGMM_OK {
					return st
				}
				*f.dst = uint64(v)
			}
			for _, f := range floats {
				var v C.double
				if st := C.sogmm_map_frame_get_f64(p, frame, f.key, &v); st != C.SOGMM_OK {
					return st
				}
				*f.dst = float64(v)
			}
			return C.sogmm_map_frame_get_pose(p, frame, &pose[0])
		})
	})
	out.Flushed = flushed != 0
	for k := range out.Pose {
		out.Pose[k] = float64(pose[k])
	}
	return out, err
}

// Export returns the map (box nil) or the components whose 3-sigma box meets
// box (x_min, y_min, z_min, x_max, y_max, z_max) as a world-frame Model.
func (m *Map) Export(box *[6]float32) (*Model, error) {
	var model *Model
	err := m.read("Export", func() error {
		if m.ptr == nil {
			return ErrClosed
		}
		defer runtime.KeepAlive(m)
		var b *C.float
		if box != nil {
			b = (*C.float)(&box[0])
		}
		var err error
		model, err = newModel(nil, func(out **C.sogmm_model, _ *C.sogmm_options) C.sogmm_status {
			return C.sogmm_map_export(out, m.ptr, b)
		})
		return err
	})
	return model, err
}

// Save writes the map as a world-frame .sogmm file with frame provenance
// (atomically; o's write keys apply). Flush pending points first.
func (m *Map) Save(path string, o *Options) error {
	cp := C.CString(path)
	defer C.free(unsafe.Pointer(cp))
	op, err := o.raw()
	if err != nil {
		return err
	}
	defer runtime.KeepAlive(o)
	return m.read("Save", func() error {
		return m.do(func(p *C.sogmm_map) C.sogmm_status { return C.sogmm_map_save(p, cp, op) })
	})
}
