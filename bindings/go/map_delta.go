package sogmm

// #include <stdlib.h>
// #include "sogmm/sogmm.h"
import "C"

import (
	"context"
	"runtime"
	"unsafe"
)

// Revision returns the map's revision: 0 when created, +1 for every insert,
// fitting flush or applied delta that changed it (SOGMM_MAP_REVISION).
func (m *Map) Revision() (uint64, error) {
	var v C.int64_t
	err := m.read("Revision", func() error {
		return m.do(func(p *C.sogmm_map) C.sogmm_status { return C.sogmm_map_get_i64(p, C.SOGMM_MAP_REVISION, &v) })
	})
	return uint64(v), err
}

// ExportDelta returns the delta file (spec/format.md section 2.5) from
// revision since to the current one: a receiver at revision since applies
// it with ApplyDelta and then holds this map bit for bit.
func (m *Map) ExportDelta(since uint64) ([]byte, error) {
	var out []byte
	err := m.read("ExportDelta", func() error {
		return m.do(func(p *C.sogmm_map) C.sogmm_status {
			var size C.size_t
			if st := C.sogmm_map_export_delta(p, C.uint64_t(since), nil, nil, 0, &size); st != C.SOGMM_OK {
				return st
			}
			buf := C.malloc(size + 1)
			defer C.free(buf)
			st := C.sogmm_map_export_delta(p, C.uint64_t(since), nil, buf, size, &size)
			if st == C.SOGMM_OK {
				out = C.GoBytes(buf, C.int(size))
			}
			return st
		})
	})
	return out, err
}

// ApplyDelta applies a delta of the sender's map. A gap, a duplicate,
// another map's or a damaged delta is refused (errors.Is ErrInvalidArg or
// ErrFormat) and the map is unchanged.
func (m *Map) ApplyDelta(delta []byte) error {
	data := C.CBytes(delta)
	defer C.free(data)
	defer runtime.KeepAlive(delta)
	return m.change(context.Background(), "ApplyDelta", func(p *C.sogmm_map) C.sogmm_status {
		return C.sogmm_map_apply_delta(p, unsafe.Pointer(data), C.size_t(len(delta)), nil)
	})
}
