package sogmm

// #include "sogmm/sogmm.h"
import "C"

import "unsafe"

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
// what the map's own frames see; 0.5 where no frame observed a point.
func (m *Map) Occupancy(xyz []float32, o *Options) (probability []float64, state []uint8, err error) {
	n, err := rowsOf(xyz, 3, "xyz")
	if err != nil {
		return nil, nil, err
	}
	probability, state = make([]float64, n), make([]uint8, n)
	err = m.read("Occupancy", func() error {
		return m.doWith(o, func(p *C.sogmm_map, op *C.sogmm_options) C.sogmm_status {
			return C.sogmm_map_occupancy_f32(p, floats(xyz), C.size_t(n), op, doubles(probability), bytesOut(state))
		})
	})
	if err != nil {
		return nil, nil, err
	}
	return probability, state, nil
}

// SurfaceDistance gives the unsigned distance (metres) of world points (rows
// of 3) to the map's surface and its gradient (rows of 3: unit vectors away
// from the nearest surface point).
func (m *Map) SurfaceDistance(xyz []float32, o *Options) (distance, gradient []float64, err error) {
	n, err := rowsOf(xyz, 3, "xyz")
	if err != nil {
		return nil, nil, err
	}
	distance, gradient = make([]float64, n), make([]float64, 3*n)
	err = m.read("SurfaceDistance", func() error {
		return m.doWith(o, func(p *C.sogmm_map, op *C.sogmm_options) C.sogmm_status {
			return C.sogmm_map_surface_distance_f32(p, floats(xyz), C.size_t(n), op, doubles(distance), doubles(gradient))
		})
	})
	if err != nil {
		return nil, nil, err
	}
	return distance, gradient, nil
}

// SurfaceDistance is Map.SurfaceDistance for a model (its frame).
func (m *Model) SurfaceDistance(xyz []float32, o *Options) (distance, gradient []float64, err error) {
	n, err := rowsOf(xyz, 3, "xyz")
	if err != nil {
		return nil, nil, err
	}
	distance, gradient = make([]float64, n), make([]float64, 3*n)
	err = m.do(o, func(p *C.sogmm_model, op *C.sogmm_options) C.sogmm_status {
		return C.sogmm_model_surface_distance_f32(p, floats(xyz), C.size_t(n), op, doubles(distance), doubles(gradient))
	})
	if err != nil {
		return nil, nil, err
	}
	return distance, gradient, nil
}

// CollisionProbability gives the probability that each ellipsoidal robot
// touches the map's surface: centers rows of 3, shapes row-major 3 x 3
// symmetric positive definite S per robot ({x : (x - c)^T S^-1 (x - c) <= 1};
// a sphere of radius r is r^2 I).
func (m *Map) CollisionProbability(centers, shapes []float64, o *Options) ([]float64, error) {
	n, err := robotsOf(centers, shapes)
	if err != nil {
		return nil, err
	}
	out := make([]float64, n)
	err = m.read("CollisionProbability", func() error {
		return m.doWith(o, func(p *C.sogmm_map, op *C.sogmm_options) C.sogmm_status {
			return C.sogmm_map_collision_probability(p, doubles(centers), doubles(shapes), C.size_t(n), op, doubles(out))
		})
	})
	if err != nil {
		return nil, err
	}
	return out, nil
}

// CollisionProbability is Map.CollisionProbability for a model (its frame).
func (m *Model) CollisionProbability(centers, shapes []float64, o *Options) ([]float64, error) {
	n, err := robotsOf(centers, shapes)
	if err != nil {
		return nil, err
	}
	out := make([]float64, n)
	err = m.do(o, func(p *C.sogmm_model, op *C.sogmm_options) C.sogmm_status {
		return C.sogmm_model_collision_probability(p, doubles(centers), doubles(shapes), C.size_t(n), op, doubles(out))
	})
	if err != nil {
		return nil, err
	}
	return out, nil
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
