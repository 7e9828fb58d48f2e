package sogmm

// #include "sogmm/sogmm.h"
import "C"

import "unsafe"

// The C queries of each handle kind, for the one Queryable implementation
// (queryable.go).

func (m *Model) query(_ string, o *Options, f func(h unsafe.Pointer, c *queryCalls, op *C.sogmm_options) C.sogmm_status) error {
	return m.do(o, func(p *C.sogmm_model, op *C.sogmm_options) C.sogmm_status {
		return f(unsafe.Pointer(p), &modelCalls, op)
	})
}

func (m *Map) query(what string, o *Options, f func(h unsafe.Pointer, c *queryCalls, op *C.sogmm_options) C.sogmm_status) error {
	return m.read(what, func() error {
		return m.doWith(o, func(p *C.sogmm_map, op *C.sogmm_options) C.sogmm_status { return f(unsafe.Pointer(p), &mapCalls, op) })
	})
}

var modelCalls = queryCalls{
	score: func(h unsafe.Pointer, points *C.float, n C.size_t, dims C.int32_t, op *C.sogmm_options, out *C.double) C.sogmm_status {
		return C.sogmm_model_score_samples_f32((*C.sogmm_model)(h), points, n, dims, op, out)
	},
	regress: func(h unsafe.Pointer, xyz *C.float, n C.size_t, op *C.sogmm_options, mean, variance *C.float) C.sogmm_status {
		return C.sogmm_model_regress_gray_f32((*C.sogmm_model)(h), xyz, n, op, mean, variance)
	},
	sample: func(h unsafe.Pointer, n C.size_t, seed C.uint64_t, dims C.int32_t, op *C.sogmm_options, out *C.float) C.sogmm_status {
		return C.sogmm_model_sample_f32((*C.sogmm_model)(h), n, seed, dims, op, out)
	},
	render: func(h unsafe.Pointer, cam *Camera, pose *C.double, op *C.sogmm_options, depth, gray, variance *C.float) C.sogmm_status {
		return C.sogmm_model_render_f32((*C.sogmm_model)(h), C.uint32_t(cam.Width), C.uint32_t(cam.Height), C.double(cam.Fx),
			C.double(cam.Fy), C.double(cam.Cx), C.double(cam.Cy), pose, op, depth, gray, variance)
	},
	distance: func(h unsafe.Pointer, xyz *C.float, n C.size_t, op *C.sogmm_options, d, g *C.double) C.sogmm_status {
		return C.sogmm_model_surface_distance_f32((*C.sogmm_model)(h), xyz, n, op, d, g)
	},
	collision: func(h unsafe.Pointer, centers, shapes *C.double, n C.size_t, op *C.sogmm_options, out *C.double) C.sogmm_status {
		return C.sogmm_model_collision_probability((*C.sogmm_model)(h), centers, shapes, n, op, out)
	},
}

var mapCalls = queryCalls{
	score: func(h unsafe.Pointer, points *C.float, n C.size_t, dims C.int32_t, op *C.sogmm_options, out *C.double) C.sogmm_status {
		return C.sogmm_map_score_samples_f32((*C.sogmm_map)(h), points, n, dims, op, out)
	},
	regress: func(h unsafe.Pointer, xyz *C.float, n C.size_t, op *C.sogmm_options, mean, variance *C.float) C.sogmm_status {
		return C.sogmm_map_regress_gray_f32((*C.sogmm_map)(h), xyz, n, op, mean, variance)
	},
	sample: func(h unsafe.Pointer, n C.size_t, seed C.uint64_t, dims C.int32_t, op *C.sogmm_options, out *C.float) C.sogmm_status {
		return C.sogmm_map_sample_f32((*C.sogmm_map)(h), n, seed, dims, op, out)
	},
	render: func(h unsafe.Pointer, cam *Camera, pose *C.double, op *C.sogmm_options, depth, gray, variance *C.float) C.sogmm_status {
		return C.sogmm_map_render_f32((*C.sogmm_map)(h), C.uint32_t(cam.Width), C.uint32_t(cam.Height), C.double(cam.Fx),
			C.double(cam.Fy), C.double(cam.Cx), C.double(cam.Cy), pose, op, depth, gray, variance)
	},
	distance: func(h unsafe.Pointer, xyz *C.float, n C.size_t, op *C.sogmm_options, d, g *C.double) C.sogmm_status {
		return C.sogmm_map_surface_distance_f32((*C.sogmm_map)(h), xyz, n, op, d, g)
	},
	collision: func(h unsafe.Pointer, centers, shapes *C.double, n C.size_t, op *C.sogmm_options, out *C.double) C.sogmm_status {
		return C.sogmm_map_collision_probability((*C.sogmm_map)(h), centers, shapes, n, op, out)
	},
}
