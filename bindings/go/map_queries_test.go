package sogmm

import (
	"context"
	"errors"
	"math"
	"slices"
	"testing"
)

// testOptions are bandwidth 0.3, seed 2, two threads and then opts (a later
// key overrides an earlier one), closed when the test ends.
func testOptions(t *testing.T, opts ...Option) *Options {
	t.Helper()
	o, err := NewOptions(append([]Option{Bandwidth(0.3), Seed(2), Threads(2)}, opts...)...)
	return held(t, o, err)
}

// newTestMap is NewMap with testOptions(t, opts...).
func newTestMap(t *testing.T, opts ...Option) *Map {
	t.Helper()
	m, err := NewMap(testOptions(t, opts...))
	if err != nil {
		t.Fatal(err)
	}
	return m
}

// twoFrameMap and its exported model, both closed when the test ends.
func twoFrameMapAndExport(t *testing.T) (*Map, *Model) {
	t.Helper()
	m := twoFrameMap(t)
	t.Cleanup(func() { m.Close() })
	return m, mustExport(t, m)
}

// A map of two posed copies of twoBlobs, flushed.
func twoFrameMap(t *testing.T) *Map {
	t.Helper()
	m := newTestMap(t, I64(OptMapBatchSize, 100000))
	pts := twoBlobs(600)
	for _, pose := range [][16]float64{yawPose(0, 0, 0, 0), yawPose(0, 3, 0, 0)} {
		if err := m.InsertPoints(context.Background(), pts, pose); err != nil {
			t.Fatal(err)
		}
	}
	if err := m.Flush(context.Background()); err != nil {
		t.Fatal(err)
	}
	return m
}

// The map's queries are bitwise the exported model's, with and without a
// progress func; a cancelled query returns ErrCancelled with its cause.
func TestMapQueriesEqualTheExportedModel(t *testing.T) {
	m, model := twoFrameMapAndExport(t)
	q4 := twoBlobs(5000)
	for i := 0; i < len(q4); i += 20 {
		q4[i] += 4 // every fifth point far off
	}
	q3 := make([]float32, 0, len(q4)/4*3)
	for i := 0; i < len(q4); i += 4 {
		q3 = append(q3, q4[i:i+3]...)
	}
	for _, c := range []struct {
		q    []float32
		dims int
	}{{q3, 3}, {q4, 4}} {
		want, err := model.ScoreSamples(context.Background(), c.q, c.dims, nil)
		if err != nil {
			t.Fatal(err)
		}
		got, err := m.ScoreSamples(context.Background(), c.q, c.dims, nil)
		if err != nil || !slices.Equal(got, want) {
			t.Fatalf("dims %d: map score differs from the model's (err %v)", c.dims, err)
		}
		var last Progress
		got, err = m.ScoreSamples(context.Background(), c.q, c.dims, reporting(nil, func(p Progress) error { last = p; return nil }))
		if err != nil || !slices.Equal(got, want) || last.Stage != StageScoring || last.Step != 5000 {
			t.Fatalf("dims %d: with progress: err %v, last %+v", c.dims, err, last)
		}
	}
	wm, wv, err := model.RegressGray(context.Background(), q3, nil)
	if err != nil {
		t.Fatal(err)
	}
	gm, gv, err := m.RegressGray(context.Background(), q3, nil)
	if err != nil || !slices.Equal(gm, wm) || !slices.Equal(gv, wv) {
		t.Fatalf("regress differs (err %v)", err)
	}
	gm, gv, err = m.RegressGray(context.Background(), q3, nil)
	if err != nil || !slices.Equal(gm, wm) || !slices.Equal(gv, wv) {
		t.Fatalf("regress with context differs (err %v)", err)
	}
	ws, _ := model.Sample(context.Background(), 3000, 4, 4, nil)
	gs, err := m.Sample(context.Background(), 3000, 4, 4, nil)
	if err != nil || !slices.Equal(gs, ws) {
		t.Fatalf("sample differs (err %v)", err)
	}
	gs, err = m.Sample(context.Background(), 3000, 4, 4, nil)
	if err != nil || !slices.Equal(gs, ws) {
		t.Fatalf("sample with context differs (err %v)", err)
	}

	ctx, cancel := context.WithCancel(context.Background())
	cancel()
	_, _, err = m.RegressGray(ctx, q3, nil)
	if !errors.Is(err, ErrCancelled) || !errors.Is(err, context.Canceled) {
		t.Fatalf("cancelled regress: %v", err)
	}
	if _, err := m.ScoreSamples(context.Background(), q3, 5, nil); !errors.Is(err, ErrInvalidArg) {
		t.Fatalf("dims 5: %v", err)
	}
	empty := mustMap(t, nil)
	if _, err := empty.Sample(context.Background(), 10, 1, 4, nil); !errors.Is(err, ErrInvalidData) {
		t.Fatalf("empty map: %v", err)
	}
}

// A cancelled insert or flush leaves the map as it was.
func TestMapInsertCancelLeavesTheMapUnchanged(t *testing.T) {
	var stages []Stage
	m := newTestMap(t, I64(OptMapNovelty, 0), OnProgress(func(p Progress) error {
		stages = append(stages, p.Stage)
		return nil
	}))
	defer m.Close()
	pts := twoBlobs(400)
	if err := m.InsertPoints(context.Background(), pts, yawPose(0, 0, 0, 0)); err != nil {
		t.Fatal(err)
	}
	if len(stages) == 0 || stages[len(stages)-1] != StageEM {
		t.Fatalf("stages %v", stages)
	}
	before, _ := m.Stats()
	stop := errors.New("stop")
	err := setProgress(m, func(Progress) error { return stop }).InsertPoints(context.Background(), pts, yawPose(0, 3, 0, 0))
	if !errors.Is(err, ErrCancelled) || !errors.Is(err, stop) {
		t.Fatalf("cancelled insert: %v", err)
	}
	if after, _ := m.Stats(); after != before {
		t.Fatalf("a cancelled insert changed the map: %+v -> %+v", before, after)
	}
	// Without a progress func (and an uncancellable ctx) nothing is installed;
	// the cancelled insert's C callback was removed after it.
	if err := setProgress(m, nil).InsertPoints(context.Background(), pts, yawPose(0, 3, 0, 0)); err != nil {
		t.Fatal(err)
	}

	p := newTestMap(t, I64(OptMapBatchSize, 100000))
	defer p.Close()
	if err := p.InsertPoints(context.Background(), pts, yawPose(0, 0, 0, 0)); err != nil {
		t.Fatal(err)
	}
	ctx, cancel := context.WithCancel(context.Background())
	cancel()
	if err := p.Flush(ctx); !errors.Is(err, context.Canceled) {
		t.Fatalf("cancelled flush: %v", err)
	}
	if s, _ := p.Stats(); s.Pending != 400 || s.Components != 0 {
		t.Fatalf("a cancelled flush changed the map: %+v", s)
	}
	if err := p.Flush(context.Background()); err != nil {
		t.Fatal(err)
	}
}

// A warm start from a fixed-K fit of the same points keeps K and does not
// lower the likelihood (EM is monotone); it refuses a K mismatch.
// The warm pass cap (OptWarmMaxIter) reaches the core through the options:
// with tol 0 EM runs its whole limit, which the fit record keeps.
func TestFitWarmPassCap(t *testing.T) {
	pts := twoBlobs(2000)
	o, _ := NewOptions(NComponents(2), Seed(1))
	defer o.Close()
	cold := mustFit(t, pts, o)
	if err := o.SetF64(OptTol, 0); err != nil {
		t.Fatal(err)
	}
	if err := o.SetI64(OptWarmMaxIter, 3); err != nil {
		t.Fatal(err)
	}
	warm, err := FitWarm(context.Background(), pts, cold, o)
	if err != nil {
		t.Fatal(err)
	}
	defer warm.Close()
	n, _ := warm.InfoI64(InfoFitIterations)
	limit, _ := warm.InfoI64(InfoFitMaxIter)
	if n != 3 || limit != 3 {
		t.Fatalf("warm pass cap 3: %d iterations, recorded limit %d", n, limit)
	}
	if err := o.SetI64(OptWarmMaxIter, -1); !errors.Is(err, ErrInvalidArg) {
		t.Fatalf("negative cap: %v", err)
	}
}

func TestFitWarm(t *testing.T) {
	pts := twoBlobs(2000)
	o, _ := NewOptions(NComponents(2), Seed(1), Threads(2))
	defer o.Close()
	cold := mustFit(t, pts, o)
	warm, err := FitWarm(context.Background(), pts, cold, o)
	if err != nil {
		t.Fatal(err)
	}
	defer warm.Close()
	mean := func(m *Model) float64 {
		s, _ := m.ScoreSamples(context.Background(), pts, 4, nil)
		var sum float64
		for _, v := range s {
			sum += v
		}
		return sum / float64(len(s))
	}
	if k, _ := warm.NComponents(); k != 2 || mean(warm) < mean(cold)-1e-6 {
		t.Fatalf("warm: K %d, mean log-likelihood %v < cold %v", k, mean(warm), mean(cold))
	}
	plain, err := FitWarm(context.Background(), pts, cold, o)
	if err != nil {
		t.Fatal(err)
	}
	defer plain.Close()
	a, _ := plain.Means()
	b, _ := warm.Means()
	if !slices.Equal(a, b) {
		t.Fatal("progress changed the warm fit")
	}
	k3, _ := NewOptions(NComponents(3))
	defer k3.Close()
	if _, err := FitWarm(context.Background(), pts, cold, k3); !errors.Is(err, ErrInvalidArg) {
		t.Fatalf("K mismatch: %v", err)
	}
	if _, err := FitWarm(context.Background(), pts, nil, nil); !errors.Is(err, ErrClosed) {
		t.Fatalf("nil initial: %v", err)
	}
}

// The model's context queries give the same values and report points.
func TestModelQueryContexts(t *testing.T) {
	_, model := twoFrameMapAndExport(t)
	q := twoBlobs(5000)
	want, _ := model.ScoreSamples(context.Background(), q, 4, nil)
	var last Progress
	got, err := model.ScoreSamples(context.Background(), q, 4, reporting(nil, func(p Progress) error { last = p; return nil }))
	if err != nil || !slices.Equal(got, want) || last.Stage != StageScoring || last.Step != 5000 {
		t.Fatalf("score with context: err %v, last %+v", err, last)
	}
	xyz := make([]float32, 0, 3*5000)
	for i := 0; i < len(q); i += 4 {
		xyz = append(xyz, q[i:i+3]...)
	}
	wm, _, _ := model.RegressGray(context.Background(), xyz, nil)
	gm, _, err := model.RegressGray(context.Background(), xyz, reporting(nil, func(p Progress) error { last = p; return nil }))
	if err != nil || !slices.Equal(gm, wm) || last.Stage != StageRegression {
		t.Fatalf("regress with context: err %v, last %+v", err, last)
	}
	stop := errors.New("stop")
	if _, err := model.ScoreSamples(context.Background(), q, 4, reporting(nil, func(Progress) error { return stop })); !errors.Is(err, stop) || !errors.Is(err, ErrCancelled) {
		t.Fatalf("cancelled score: %v", err)
	}
}

// OptMapNoveltyBandwidthScale is range-checked and reaches the map's fits: a
// finer scale gives the same batch more components. The batch is two frames
// of the same size 3 m apart (h = 1/2 of its point pairs from one frame, so
// it is fitted at 0.05 x (s + (1 - s) / 4)); one frame alone would be fitted
// at the bandwidth itself, whatever the scale.
func TestNoveltyBandwidthScale(t *testing.T) {
	for _, bad := range []float64{0, 1.5} {
		if _, err := NewOptions(F64(OptMapNoveltyBandwidthScale, bad)); err == nil {
			t.Fatalf("scale %g was accepted", bad)
		}
	}
	count := func(scale float64) uint64 {
		m := newTestMap(t, Bandwidth(0.05), I64(OptMapBatchSize, 100000), F64(OptMapNoveltyBandwidthScale, scale))
		defer m.Close()
		for _, x := range []float64{0, 3} {
			if err := m.InsertPoints(context.Background(), twoBlobs(600), yawPose(0, x, 0, 0)); err != nil {
				t.Fatal(err)
			}
		}
		if err := m.Flush(context.Background()); err != nil {
			t.Fatal(err)
		}
		st, err := m.Stats()
		if err != nil {
			t.Fatal(err)
		}
		return st.Components
	}
	if fine, coarse := count(0.1), count(1.0); fine <= coarse {
		t.Fatalf("scale 0.1 gave %d components, scale 1 %d", fine, coarse)
	}
}

// OptMapRevisitRefitRatio is range-checked and reaches the map: a wall seen
// in one gray (one batch), then again in 8 gray stripes, has many more modes
// than the map has components there, so a second fit replaces them at the
// default ratio and not at ratio 0.
func TestRevisitRefitRatio(t *testing.T) {
	for _, bad := range []float64{0.5, -1, math.NaN(), math.Inf(1)} {
		if _, err := NewOptions(F64(OptMapRevisitRefitRatio, bad)); err == nil {
			t.Fatalf("ratio %g was accepted", bad)
		}
	}
	const w, h = 64, 48
	depth := make([]uint16, w*h)
	plain := make([]uint8, w*h)
	striped := make([]uint8, w*h)
	for i := range depth {
		depth[i] = 1500
		plain[i] = 128
		striped[i] = uint8(32 * (((i % w) / 4) % 8))
	}
	fits := func(opts ...Option) uint64 {
		m := newTestMap(t, append([]Option{Bandwidth(0.02), I64(OptMapBatchSize, w*h)}, opts...)...)
		defer m.Close()
		for _, gray := range [][]uint8{plain, striped} {
			f := Frame{Depth: depth, Gray8: gray, Width: w, Height: h, Fx: 60, Fy: 60, Cx: 32, Cy: 24}
			if err := m.InsertRGBD(context.Background(), f, yawPose(0, 0, 0, 0)); err != nil {
				t.Fatal(err)
			}
		}
		st, err := m.Stats()
		if err != nil {
			t.Fatal(err)
		}
		if st.Pending != 0 {
			t.Fatalf("%d points pending", st.Pending)
		}
		f0, err := m.FrameStats(0)
		if err != nil {
			t.Fatal(err)
		}
		f1, err := m.FrameStats(1)
		if err != nil {
			t.Fatal(err)
		}
		if f0.Replaced != 0 || (f1.Replaced > 0) != (st.Flushes == 2) || f1.Flushed != (st.Flushes == 2) ||
			st.Refits != st.Flushes-1 {
			t.Fatalf("frame stats %+v, %+v with %d fits", f0, f1, st.Flushes)
		}
		return st.Flushes
	}
	if got := fits(); got != 2 {
		t.Fatalf("default ratio: %d fits, want 2 (the revisit refits)", got)
	}
	if got := fits(F64(OptMapRevisitRefitRatio, 0)); got != 1 {
		t.Fatalf("ratio 0: %d fits, want 1", got)
	}
}
