package sogmm

// #include "sogmm/sogmm.h"
import "C"

import (
	"context"
	"unsafe"
)

// What a planner asks a map (issue 31; sogmm.h, sogmm_map_occupancy_f32,
// sogmm_*_surface_distance_f32, sogmm_*_collision_probability). Options (nil
// = defaults): OptOccupancySigma, OptOccupancyThickness, OptSurfaceDiscSigmas,
// Threads.

const (
	OccupancyFree     = C.SOGMM_OCCUPANCY_FREE
	OccupancyOccupied = C.SOGMM_OCCUPANCY_OCCUPIED
	OccupancyUnknown  = C.SOGMM_OCCUPANCY_UNKNOWN
)

// Occupancy gives P(occupied) in [0, 1] of world points (xyz: rows of 3)
// and their states (OccupancyFree, OccupancyOccupied, OccupancyUnknown) from
// what the map's own frames see; 0.5 where no frame observed a point. ctx
// and the progress func of o as Queryable (a Map's only query that a Model
// lacks: it needs the frames).
func (m *Map) Occupancy(ctx context.Context, xyz []float32, o *Options) (probability []float64, state []uint8, err error) {
	n, err := rowsOf(xyz, 3, "xyz")
	if err != nil {
		return nil, nil, err
	}
	probability, state = make([]float64, n), make([]uint8, n)
	_, err = withProgress(ctx, o, func(o *Options) (struct{}, error) {
		return struct{}{}, m.query("Occupancy", o, func(h unsafe.Pointer, _ *queryCalls, op *C.sogmm_options) C.sogmm_status {
			return C.sogmm_map_occupancy_f32((*C.sogmm_map)(h), floats(xyz), C.size_t(n), op, doubles(probability), bytesOut(state))
		})
	})
	if err != nil {
		return nil, nil, err
	}
	return probability, state, nil
}

// robotsOf checks that centers holds n rows of 3 and shapes n matrices of 9.
func robotsOf(centers, shapes []float64) (int, error) {
	if len(centers)%3 != 0 || len(shapes) != 3*len(centers) {
		return 0, invalidArg("centers must hold rows of 3 and shapes 9 values per centre (got %d and %d)",
			len(centers), len(shapes))
	}
	return len(centers) / 3, nil
}

func bytesOut(s []uint8) *C.uint8_t {
	if len(s) == 0 {
		return nil
	}
	return (*C.uint8_t)(unsafe.Pointer(&s[0]))
}
