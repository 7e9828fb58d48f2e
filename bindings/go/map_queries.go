package sogmm

// #include "sogmm/sogmm.h"
import "C"

import "context"

// World-frame queries on a map without exporting it: each answer is bitwise
// what the same Model query gives on m.Export(nil) (sogmm.h,
// sogmm_map_score_samples_f32). They only read the map, so they may run
// concurrently with each other (not with inserts or Close). A map without
// components (nothing flushed yet) gives ErrInvalidData.

// ScoreSamples is the log-density of world points, rows of dims floats (4:
// joint; 3: marginal over gray).
func (m *Map) ScoreSamples(points []float32, dims int) ([]float64, error) {
	return m.scoreSamples(points, dims, nil)
}

// ScoreSamplesContext is ScoreSamplesWith (the Threads and
// QueryTruncationNats of o; nil = exact, all cores) with cancellation and
// progress (StageScoring) as FitContext.
func (m *Map) ScoreSamplesContext(ctx context.Context, points []float32, dims int, o *Options, fn ProgressFunc) ([]float64, error) {
	return withProgress(ctx, o, fn, func(p *Options) ([]float64, error) { return m.scoreSamples(points, dims, p) })
}

// ScoreSamplesWith is ScoreSamples with the Threads and QueryTruncationNats
// of o, as Model.ScoreSamplesWith.
func (m *Map) ScoreSamplesWith(points []float32, dims int, o *Options) ([]float64, error) {
	return m.scoreSamples(points, dims, o)
}

func (m *Map) scoreSamples(points []float32, dims int, o *Options) ([]float64, error) {
	n, out, err := scoreBuffer(points, dims)
	if err != nil {
		return nil, err
	}
	err = m.read("ScoreSamples", func() error {
		return m.doWith(o, func(p *C.sogmm_map, op *C.sogmm_options) C.sogmm_status {
			return C.sogmm_map_score_samples_f32(p, floats(points), C.size_t(n), C.int32_t(dims), op, doubles(out))
		})
	})
	if err != nil {
		return nil, err
	}
	return out, nil
}

// RegressGray gives the expected gray and its variance at world points (xyz:
// rows of 3).
func (m *Map) RegressGray(xyz []float32) (mean, variance []float32, err error) {
	return m.regressGray(xyz, nil)
}

// RegressGrayContext is RegressGrayWith (options as ScoreSamplesContext)
// with cancellation and progress (StageRegression) as FitContext.
func (m *Map) RegressGrayContext(ctx context.Context, xyz []float32, o *Options, fn ProgressFunc) (mean, variance []float32, err error) {
	both, err := withProgress(ctx, o, fn, func(p *Options) ([2][]float32, error) {
		mean, variance, err := m.regressGray(xyz, p)
		return [2][]float32{mean, variance}, err
	})
	return both[0], both[1], err
}

// RegressGrayWith is RegressGray with the Threads and QueryTruncationNats of
// o, as Model.RegressGrayWith.
func (m *Map) RegressGrayWith(xyz []float32, o *Options) (mean, variance []float32, err error) {
	return m.regressGray(xyz, o)
}

func (m *Map) regressGray(xyz []float32, o *Options) (mean, variance []float32, err error) {
	n, err := rowsOf(xyz, 3, "xyz")
	if err != nil {
		return nil, nil, err
	}
	mean, variance = make([]float32, n), make([]float32, n)
	err = m.read("RegressGray", func() error {
		return m.doWith(o, func(p *C.sogmm_map, op *C.sogmm_options) C.sogmm_status {
			return C.sogmm_map_regress_gray_f32(p, floats(xyz), C.size_t(n), op, floats(mean), floats(variance))
		})
	})
	if err != nil {
		return nil, nil, err
	}
	return mean, variance, nil
}

// Sample draws n world points as rows of dims floats, grouped by component;
// o (may be nil) gives the truncation. Same seed, same samples.
func (m *Map) Sample(n int, seed uint64, dims int, o *Options) ([]float32, error) {
	out, err := sampleBuffer(n, dims)
	if err != nil {
		return nil, err
	}
	err = m.read("Sample", func() error {
		return m.doWith(o, func(p *C.sogmm_map, op *C.sogmm_options) C.sogmm_status {
			return C.sogmm_map_sample_f32(p, C.size_t(n), C.uint64_t(seed), C.int32_t(dims), op, floats(out))
		})
	})
	if err != nil {
		return nil, err
	}
	return out, nil
}

// SampleContext is Sample with cancellation and progress (StageSampling) as FitContext.
func (m *Map) SampleContext(ctx context.Context, n int, seed uint64, dims int, o *Options, fn ProgressFunc) ([]float32, error) {
	return withProgress(ctx, o, fn, func(p *Options) ([]float32, error) { return m.Sample(n, seed, dims, p) })
}

// InsertPointsContext is InsertPoints with cancellation and progress of the
// fit the insert may run (as FitContext). A cancelled insert leaves the map
// as it was.
func (m *Map) InsertPointsContext(ctx context.Context, points []float32, pose [16]float64, fn ProgressFunc) error {
	return m.insertPoints(points, pose, &mapProgress{ctx, fn})
}

// InsertRGBDContext is InsertRGBD with cancellation and progress as InsertPointsContext.
func (m *Map) InsertRGBDContext(ctx context.Context, f Frame, pose [16]float64, fn ProgressFunc) error {
	return m.insertRGBD(f, pose, &mapProgress{ctx, fn})
}

// FlushContext is Flush with cancellation and progress; a cancelled flush
// keeps the pending points.
func (m *Map) FlushContext(ctx context.Context, fn ProgressFunc) error {
	return m.flush(&mapProgress{ctx, fn})
}
