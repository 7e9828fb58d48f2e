package sogmm

import (
	"context"
	"errors"
	"math"
	"os"
	"path/filepath"
	"slices"
	"strings"
	"testing"
)

// ---- PSNRImages ----------------------------------------------------------

// Pixels and the error e = 1/8 are exact in float32: a constant error e gives
// 10 log10(R^2 / e^2); the pixel at -1 is empty.
var (
	psnrTruth    = []float32{0.25, 0.5, -1, 0.75}
	psnrEstimate = []float32{0.375, 0.625, -1, 0.875}
)

const psnrE = 0.125

func near(a, b float64) bool { return math.Abs(a-b) < 1e-12 }

func TestPSNRImagesClosedForm(t *testing.T) {
	r, err := PSNRImages(psnrTruth, psnrEstimate, 1)
	if err != nil {
		t.Fatal(err)
	}
	if !near(r.PSNR, 10*math.Log10(1/(psnrE*psnrE))) {
		t.Fatalf("honest %v", r)
	}
	// Paper figure: range 2, all 4 pixels counted, the empty one as perfect.
	if !near(r.Paper, 10*math.Log10(4/(3*psnrE*psnrE/4))) {
		t.Fatalf("paper %v", r)
	}
	// Range 2 adds exactly 20 log10 2; the paper figure ignores the range.
	two, err := PSNRImages(psnrTruth, psnrEstimate, 2)
	if err != nil || !near(two.PSNR-r.PSNR, 20*math.Log10(2)) || two.Paper != r.Paper {
		t.Fatalf("range 2: %v %v", two, err)
	}
	// Range 0: the valid truth's range, 0.75 - 0.25.
	auto, err := PSNRImages(psnrTruth, psnrEstimate, 0)
	if err != nil || !near(auto.PSNR, 10*math.Log10(0.25/(psnrE*psnrE))) {
		t.Fatalf("range 0: %v %v", auto, err)
	}
	same, err := PSNRImages(psnrTruth, psnrTruth, 1)
	if err != nil || !math.IsInf(same.PSNR, 1) || !math.IsInf(same.Paper, 1) {
		t.Fatalf("identical: %v %v", same, err)
	}
}

func TestPSNRImagesRefusesBadInput(t *testing.T) {
	_, err := PSNRImages(psnrTruth, psnrEstimate[:3], 1)
	if !errors.Is(err, ErrInvalidArg) || !strings.Contains(err.Error(), "same size") {
		t.Fatalf("lengths: %v", err)
	}
	for _, r := range []float64{-1, math.NaN(), math.Inf(1)} {
		_, err := PSNRImages(psnrTruth, psnrEstimate, r)
		if !errors.Is(err, ErrInvalidArg) || !strings.Contains(err.Error(), "data range") {
			t.Fatalf("range %v: %v", r, err)
		}
	}
	for name, c := range map[string][2][]float32{
		"no valid pixel": {{-1, -1}, {0, 0}},
		"NaN":            {psnrTruth, {float32(math.NaN()), 0, 0, 0}},
		"empty":          {{}, {}},
	} {
		if _, err := PSNRImages(c[0], c[1], 1); !errors.Is(err, ErrInvalidData) {
			t.Fatalf("%s: %v", name, err)
		}
	}
}

// ---- SetInfoF64 / SetInfoI64 ---------------------------------------------

func twoComponents(t *testing.T) *Model {
	t.Helper()
	cov := make([]float32, 32)
	for k := 0; k < 2; k++ {
		for i := 0; i < 4; i++ {
			cov[16*k+5*i] = 0.01 * float32(i+1)
		}
	}
	m, err := FromArrays([]float32{0.25, 0.75}, []float32{0, 1, 2, 3, 4, 5, 6, 7}, cov, 40)
	return held(t, m, err)
}

func TestSetInfoRoundTripsThroughAFile(t *testing.T) {
	m := twoComponents(t)
	if _, err := m.InfoI64(InfoFitIterations); !errors.Is(err, ErrNotFound) {
		t.Fatalf("a model from arrays has no fit record: %v", err)
	}
	must := func(err error) {
		t.Helper()
		if err != nil {
			t.Fatal(err)
		}
	}
	must(m.SetInfoI64(InfoFitIterations, 40))
	must(m.SetInfoI64(InfoFitConverged, 1))
	must(m.SetInfoF64(InfoFitBandwidth, 0.02))
	must(m.SetInfoF64(InfoFitLogLik, -3.25))
	seed := uint64(1) << 63
	must(m.SetInfoI64(InfoFitSeed, int64(seed))) // the uint64's bits
	must(m.SetInfoI64(InfoCameraDecimate, 5))
	must(m.SetInfoF64(InfoCameraFx, 525.5))
	path := filepath.Join(t.TempDir(), "info.sogmm")
	must(m.Save(path, nil))
	back, err := Load(path, nil)
	must(err)
	defer back.Close()
	for _, model := range []*Model{m, back} {
		for key, want := range map[Key]int64{InfoFitIterations: 40, InfoFitConverged: 1, InfoFitSeed: math.MinInt64,
			InfoCameraDecimate: 5} {
			if got, err := model.InfoI64(key); err != nil || got != want {
				t.Fatalf("key %d: %d %v, want %d", key, got, err, want)
			}
		}
		for key, want := range map[Key]float64{InfoFitBandwidth: 0.02, InfoFitLogLik: -3.25, InfoCameraFx: 525.5} {
			if got, err := model.InfoF64(key); err != nil || got != want {
				t.Fatalf("key %d: %v %v, want %v", key, got, err, want)
			}
		}
	}
	os.Remove(path)
}

func TestSetInfoRefusesWhatFilesCannotHold(t *testing.T) {
	m := twoComponents(t)
	if err := m.SetInfoI64(InfoFitIterations, 7); err != nil {
		t.Fatal(err)
	}
	for i, err := range []error{
		m.SetInfoI64(InfoSupportSize, 3),           // not a stored info key
		m.SetInfoI64(InfoFitConverged, 2),          // 0 or 1
		m.SetInfoI64(InfoFitIterations, 1<<31),     // an int32 field
		m.SetInfoI64(InfoCameraDecimate, 0),        // >= 1
		m.SetInfoF64(InfoFitBandwidth, math.NaN()), // finite
	} {
		if !errors.Is(err, ErrInvalidArg) {
			t.Fatalf("refused value %d: %v", i, err)
		}
	}
	if n, err := m.InfoI64(InfoFitIterations); err != nil || n != 7 {
		t.Fatalf("iterations changed: %d %v", n, err)
	}
	if s, err := m.InfoI64(InfoSupportSize); err != nil || s != 40 {
		t.Fatalf("support changed: %d %v", s, err)
	}
}

// ---- QueryTruncationNats and query threads --------------------------------

// farCluster: component 0 at the origin (gray 0.25) and 9 components 4 sigma
// away along x (gray 0.75): at the query points those 9 terms are 8+ nats
// below the first, more than a probe keeps (8), so culling at 2 or 6 nats
// skips some.
func farCluster(t *testing.T) *Model {
	t.Helper()
	const m = 10
	cov := make([]float32, 16*m)
	for k := 0; k < m; k++ {
		for i := 0; i < 4; i++ {
			cov[16*k+5*i] = 1
		}
	}
	means := []float32{0, 0, 0, 0.25}
	for k := 1; k < m; k++ {
		means = append(means, 4, 0.25*float32(k-1), 0, 0.75)
	}
	weights := make([]float32, m)
	for k := range weights {
		weights[k] = 0.1
	}
	model, err := FromArrays(weights, means, cov, 1000) // a known support: a map refuses 0 (unknown)
	return held(t, model, err)
}

var (
	cullQuery    = []float32{0, 0, 0, 0.25, 0, 0.5, 0, 0.5, -1, 0, 0, 0.25}
	cullQueryXYZ = []float32{0, 0, 0, 0, 0.5, 0, -1, 0, 0}
)

func culled(t *testing.T, nats float64, threads int64) *Options {
	t.Helper()
	o, err := NewOptions(QueryTruncationNats(nats), Threads(threads))
	return held(t, o, err)
}

func TestCulledQueriesWithinTheBound(t *testing.T) {
	m := farCluster(t)
	const M = 10.0
	exact, err := m.ScoreSamples(context.Background(), cullQuery, 4, nil)
	if err != nil {
		t.Fatal(err)
	}
	mean, variance, err := m.RegressGray(context.Background(), cullQueryXYZ, nil)
	if err != nil {
		t.Fatal(err)
	}
	for _, nats := range []float64{2, 6} {
		c, err := m.ScoreSamples(context.Background(), cullQuery, 4, culled(t, nats, 1))
		if err != nil {
			t.Fatal(err)
		}
		c2, err := m.ScoreSamples(context.Background(), cullQuery, 4, culled(t, nats, 2))
		if err != nil || !slices.Equal(c, c2) {
			t.Fatalf("thread count changed bits: %v %v %v", c, c2, err)
		}
		bound := math.Log1p(M * math.Exp(-nats))
		for i := range c {
			if c[i] > exact[i] || exact[i]-c[i] > bound {
				t.Fatalf("nats %v: exact %v culled %v bound %v", nats, exact[i], c[i], bound)
			}
		}
		if slices.Equal(c, exact) {
			t.Fatalf("nothing was culled at %v nats", nats)
		}
		// Dropped components hold a share <= (M - 1) e^-nats at a point and
		// every conditional gray is in [0.25, 0.75]: the mean moves by at
		// most 0.5 times that share.
		cm, cv, err := m.RegressGray(context.Background(), cullQueryXYZ, culled(t, nats, 2))
		if err != nil {
			t.Fatal(err)
		}
		shift := 0.5 * (M - 1) * math.Exp(-nats)
		for i := range cm {
			if math.Abs(float64(cm[i]-mean[i])) > shift || !(cv[i] > 0) {
				t.Fatalf("nats %v: mean %v vs %v, variance %v", nats, cm, mean, cv)
			}
		}
		if slices.Equal(cm, mean) {
			t.Fatalf("regression: nothing was culled at %v nats", nats)
		}
	}
	// Far above every gap: nothing is culled, the exact bits.
	c, err := m.ScoreSamples(context.Background(), cullQuery, 4, culled(t, 40, 2))
	if err != nil || !slices.Equal(c, exact) {
		t.Fatalf("40 nats: %v %v", c, err)
	}
	cm, cv, err := m.RegressGray(context.Background(), cullQueryXYZ, culled(t, 40, 1))
	if err != nil || !slices.Equal(cm, mean) || !slices.Equal(cv, variance) {
		t.Fatalf("40 nats regression: %v %v %v", cm, cv, err)
	}
}

func TestMapQueriesTakeTheSameOptions(t *testing.T) {
	m := farCluster(t)
	if err := m.SetValue("coordinate_frame", "world"); err != nil {
		t.Fatal(err)
	}
	mp := mustLoadMap(t, savedFile(t, m, "far.sogmm"))
	o := culled(t, 2, 2)
	c, err := mp.ScoreSamples(context.Background(), cullQuery, 4, o)
	if err != nil {
		t.Fatal(err)
	}
	want, _ := m.ScoreSamples(context.Background(), cullQuery, 4, o)
	exact, _ := mp.ScoreSamples(context.Background(), cullQuery, 4, nil)
	if !slices.Equal(c, want) || slices.Equal(c, exact) {
		t.Fatalf("map %v, model %v, exact %v", c, want, exact)
	}
	cm, _, err := mp.RegressGray(context.Background(), cullQueryXYZ, o)
	if err != nil {
		t.Fatal(err)
	}
	wm, _, _ := m.RegressGray(context.Background(), cullQueryXYZ, o)
	em, _, _ := mp.RegressGray(context.Background(), cullQueryXYZ, nil)
	if !slices.Equal(cm, wm) || slices.Equal(cm, em) {
		t.Fatalf("map %v, model %v, exact %v", cm, wm, em)
	}
	// The context variants take the same options, and report every point.
	for name, score := range map[string]func(*Options, ProgressFunc) ([]float64, error){
		"map": func(o *Options, fn ProgressFunc) ([]float64, error) {
			return mp.ScoreSamples(context.Background(), cullQuery, 4, reporting(o, fn))
		},
		"model": func(o *Options, fn ProgressFunc) ([]float64, error) {
			return m.ScoreSamples(context.Background(), cullQuery, 4, reporting(o, fn))
		},
	} {
		var last Progress
		got, err := score(o, func(p Progress) error { last = p; return nil })
		if err != nil || !slices.Equal(got, c) || last.Stage != StageScoring || last.Step != 3 {
			t.Fatalf("%s score with context: %v vs %v, err %v, last %+v", name, got, c, err, last)
		}
	}
	for name, regress := range map[string]func(*Options) ([]float32, []float32, error){
		"map": func(o *Options) ([]float32, []float32, error) {
			return mp.RegressGray(context.Background(), cullQueryXYZ, o)
		},
		"model": func(o *Options) ([]float32, []float32, error) {
			return m.RegressGray(context.Background(), cullQueryXYZ, o)
		},
	} {
		if got, _, err := regress(o); err != nil || !slices.Equal(got, cm) {
			t.Fatalf("%s regress with context: %v vs %v, err %v", name, got, cm, err)
		}
	}
}

func TestInvalidCullingOrThreadsAreRefused(t *testing.T) {
	for _, v := range []float64{-1, math.NaN(), math.Inf(1)} {
		if _, err := NewOptions(QueryTruncationNats(v)); !errors.Is(err, ErrInvalidArg) {
			t.Fatalf("nats %v: %v", v, err)
		}
	}
	if _, err := NewOptions(Threads(-1)); !errors.Is(err, ErrInvalidArg) {
		t.Fatalf("threads -1: %v", err)
	}
}

// ---- the writer keeps to the reader's decoded-size cap --------------------

func TestSaveAboveTheDecodedSizeCapIsRefused(t *testing.T) {
	m := twoComponents(t) // 2 x 15 float32 values: 120 decoded bytes
	capped := func(c int64) *Options {
		o, err := NewOptions(I64(OptMaxDecodedBytes, c))
		return held(t, o, err)
	}
	_, err := m.Bytes(capped(119))
	if !errors.Is(err, ErrLimit) || !strings.Contains(err.Error(), "over the cap of 119 bytes") {
		t.Fatalf("cap 119: %v", err)
	}
	data, err := m.Bytes(capped(120))
	if err != nil {
		t.Fatal(err)
	}
	back, err := FromBytes(data, capped(120))
	if err != nil {
		t.Fatal(err)
	}
	defer back.Close()
}
