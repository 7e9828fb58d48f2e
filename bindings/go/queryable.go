package sogmm

// #include "sogmm/sogmm.h"
import "C"

import (
	"context"
	"unsafe"
)

// Queryable is what a Model (in its own frame) and a Map (in the world frame,
// without exporting it; the same bits as the Model its Export gives) both
// answer. The calls only read: they may run concurrently with each other (on
// a Map not with inserts or Close). Each takes a ctx that cancels it (an
// error satisfying errors.Is(err, ErrCancelled) and errors.Is(err,
// ctx.Err())) and options o (nil = defaults) whose progress func
// (OnProgress) receives its reports. A Map without components (nothing
// flushed yet) gives ErrInvalidData.
type Queryable interface {
	// ScoreSamples is the log-density of rows of dims floats (4: joint; 3:
	// marginal over gray), with the Threads and QueryTruncationNats of o
	// (each culled score is at most ln(1 + M e^-nats) below the exact one).
	// Progress: StageScoring.
	ScoreSamples(ctx context.Context, points []float32, dims int, o *Options) ([]float64, error)
	// RegressGray gives the expected gray and its conditional variance at
	// points (xyz: rows of 3); options as ScoreSamples. Progress: StageRegression.
	RegressGray(ctx context.Context, xyz []float32, o *Options) (mean, variance []float32, err error)
	// Sample draws n points as rows of dims floats (4: x, y, z, gray; 3: x,
	// y, z), grouped by component; o gives the truncation. Same seed, same
	// samples. Progress: StageSampling.
	Sample(ctx context.Context, n int, seed uint64, dims int, o *Options) ([]float32, error)
	// Render is what shows from cam at pose (camera-to-world; nil = identity):
	// per pixel the first surface along its ray, its depth, the gray
	// regressed there and its variance. o gives DepthMin / DepthMax (the
	// depths that count as surfaces) and Threads (the same bits for any
	// count). Progress: StageRendering (rows done).
	Render(ctx context.Context, cam Camera, pose *[16]float64, o *Options) (*Rendered, error)
	// SurfaceDistance gives the unsigned distance (metres) of points (rows of
	// 3) to the surface and its gradient (rows of 3: unit vectors away from
	// the nearest surface point); o: OptSurfaceDiscSigmas, Threads.
	SurfaceDistance(ctx context.Context, xyz []float32, o *Options) (distance, gradient []float64, err error)
	// CollisionProbability gives the probability that each ellipsoidal robot
	// touches the surface: centers rows of 3, shapes row-major 3 x 3
	// symmetric positive definite S per robot ({x : (x - c)^T S^-1 (x - c) <=
	// 1}; a sphere of radius r is r^2 I); o as SurfaceDistance.
	CollisionProbability(ctx context.Context, centers, shapes []float64, o *Options) ([]float64, error)
}

var (
	_ Queryable = (*Model)(nil)
	_ Queryable = (*Map)(nil)
)

// queryCalls are the C queries of one handle kind (sogmm_model_* or
// sogmm_map_*) on its untyped handle: the one thing that differs between the
// Queryable of a Model and of a Map.
type queryCalls struct {
	score     func(h unsafe.Pointer, points *C.float, n C.size_t, dims C.int32_t, op *C.sogmm_options, out *C.double) C.sogmm_status
	regress   func(h unsafe.Pointer, xyz *C.float, n C.size_t, op *C.sogmm_options, mean, variance *C.float) C.sogmm_status
	sample    func(h unsafe.Pointer, n C.size_t, seed C.uint64_t, dims C.int32_t, op *C.sogmm_options, out *C.float) C.sogmm_status
	render    func(h unsafe.Pointer, cam *Camera, pose *C.double, op *C.sogmm_options, depth, gray, variance *C.float) C.sogmm_status
	distance  func(h unsafe.Pointer, xyz *C.float, n C.size_t, op *C.sogmm_options, d, g *C.double) C.sogmm_status
	collision func(h unsafe.Pointer, centers, shapes *C.double, n C.size_t, op *C.sogmm_options, out *C.double) C.sogmm_status
}

// querier runs one read-only C call on its handle (a Map holds its use guard
// for reading meanwhile) with o's handle (nil = defaults) and its kind's calls.
type querier interface {
	query(what string, o *Options, f func(h unsafe.Pointer, c *queryCalls, op *C.sogmm_options) C.sogmm_status) error
}

func scoreSamples(q querier, ctx context.Context, points []float32, dims int, o *Options) ([]float64, error) {
	n, out, err := scoreBuffer(points, dims)
	if err != nil {
		return nil, err
	}
	return withProgress(ctx, o, func(o *Options) ([]float64, error) {
		err := q.query("ScoreSamples", o, func(h unsafe.Pointer, c *queryCalls, op *C.sogmm_options) C.sogmm_status {
			return c.score(h, floats(points), C.size_t(n), C.int32_t(dims), op, doubles(out))
		})
		return orNil(out, err)
	})
}

func regressGray(q querier, ctx context.Context, xyz []float32, o *Options) (mean, variance []float32, err error) {
	n, err := rowsOf(xyz, 3, "xyz")
	if err != nil {
		return nil, nil, err
	}
	mean, variance = make([]float32, n), make([]float32, n)
	_, err = withProgress(ctx, o, func(o *Options) (struct{}, error) {
		return struct{}{}, q.query("RegressGray", o, func(h unsafe.Pointer, c *queryCalls, op *C.sogmm_options) C.sogmm_status {
			return c.regress(h, floats(xyz), C.size_t(n), op, floats(mean), floats(variance))
		})
	})
	if err != nil {
		return nil, nil, err
	}
	return mean, variance, nil
}

func sample(q querier, ctx context.Context, n int, seed uint64, dims int, o *Options) ([]float32, error) {
	out, err := sampleBuffer(n, dims)
	if err != nil {
		return nil, err
	}
	return withProgress(ctx, o, func(o *Options) ([]float32, error) {
		err := q.query("Sample", o, func(h unsafe.Pointer, c *queryCalls, op *C.sogmm_options) C.sogmm_status {
			return c.sample(h, C.size_t(n), C.uint64_t(seed), C.int32_t(dims), op, floats(out))
		})
		return orNil(out, err)
	})
}

func render(q querier, ctx context.Context, cam Camera, pose *[16]float64, o *Options) (*Rendered, error) {
	return withProgress(ctx, o, func(o *Options) (*Rendered, error) {
		return renderInto(cam, func(depth, gray, variance *C.float) error {
			return q.query("Render", o, func(h unsafe.Pointer, c *queryCalls, op *C.sogmm_options) C.sogmm_status {
				return c.render(h, &cam, posePtr(pose), op, depth, gray, variance)
			})
		})
	})
}

func surfaceDistance(q querier, ctx context.Context, xyz []float32, o *Options) (distance, gradient []float64, err error) {
	n, err := rowsOf(xyz, 3, "xyz")
	if err != nil {
		return nil, nil, err
	}
	distance, gradient = make([]float64, n), make([]float64, 3*n)
	_, err = withProgress(ctx, o, func(o *Options) (struct{}, error) {
		return struct{}{}, q.query("SurfaceDistance", o, func(h unsafe.Pointer, c *queryCalls, op *C.sogmm_options) C.sogmm_status {
			return c.distance(h, floats(xyz), C.size_t(n), op, doubles(distance), doubles(gradient))
		})
	})
	if err != nil {
		return nil, nil, err
	}
	return distance, gradient, nil
}

func collisionProbability(q querier, ctx context.Context, centers, shapes []float64, o *Options) ([]float64, error) {
	n, err := robotsOf(centers, shapes)
	if err != nil {
		return nil, err
	}
	out := make([]float64, n)
	return withProgress(ctx, o, func(o *Options) ([]float64, error) {
		err := q.query("CollisionProbability", o, func(h unsafe.Pointer, c *queryCalls, op *C.sogmm_options) C.sogmm_status {
			return c.collision(h, doubles(centers), doubles(shapes), C.size_t(n), op, doubles(out))
		})
		return orNil(out, err)
	})
}

// orNil is out, or nil with a failed call's error.
func orNil[T any](out []T, err error) ([]T, error) {
	if err != nil {
		return nil, err
	}
	return out, nil
}

// ScoreSamples: see Queryable.
func (m *Model) ScoreSamples(ctx context.Context, points []float32, dims int, o *Options) ([]float64, error) {
	return scoreSamples(m, ctx, points, dims, o)
}

// RegressGray: see Queryable.
func (m *Model) RegressGray(ctx context.Context, xyz []float32, o *Options) (mean, variance []float32, err error) {
	return regressGray(m, ctx, xyz, o)
}

// Sample: see Queryable.
func (m *Model) Sample(ctx context.Context, n int, seed uint64, dims int, o *Options) ([]float32, error) {
	return sample(m, ctx, n, seed, dims, o)
}

// Render: see Queryable (pose nil: the model in the camera's frame).
func (m *Model) Render(ctx context.Context, cam Camera, pose *[16]float64, o *Options) (*Rendered, error) {
	return render(m, ctx, cam, pose, o)
}

// SurfaceDistance: see Queryable.
func (m *Model) SurfaceDistance(ctx context.Context, xyz []float32, o *Options) (distance, gradient []float64, err error) {
	return surfaceDistance(m, ctx, xyz, o)
}

// CollisionProbability: see Queryable.
func (m *Model) CollisionProbability(ctx context.Context, centers, shapes []float64, o *Options) ([]float64, error) {
	return collisionProbability(m, ctx, centers, shapes, o)
}

// ScoreSamples: see Queryable (world points).
func (m *Map) ScoreSamples(ctx context.Context, points []float32, dims int, o *Options) ([]float64, error) {
	return scoreSamples(m, ctx, points, dims, o)
}

// RegressGray: see Queryable (world points).
func (m *Map) RegressGray(ctx context.Context, xyz []float32, o *Options) (mean, variance []float32, err error) {
	return regressGray(m, ctx, xyz, o)
}

// Sample: see Queryable (world points).
func (m *Map) Sample(ctx context.Context, n int, seed uint64, dims int, o *Options) ([]float32, error) {
	return sample(m, ctx, n, seed, dims, o)
}

// Render: see Queryable (the map seen from the camera-to-world pose).
func (m *Map) Render(ctx context.Context, cam Camera, pose *[16]float64, o *Options) (*Rendered, error) {
	return render(m, ctx, cam, pose, o)
}

// SurfaceDistance: see Queryable (world points).
func (m *Map) SurfaceDistance(ctx context.Context, xyz []float32, o *Options) (distance, gradient []float64, err error) {
	return surfaceDistance(m, ctx, xyz, o)
}

// CollisionProbability: see Queryable (robots in the world frame).
func (m *Map) CollisionProbability(ctx context.Context, centers, shapes []float64, o *Options) ([]float64, error) {
	return collisionProbability(m, ctx, centers, shapes, o)
}
