package sogmm

import (
	"context"
	"errors"
	"fmt"
	"math"
	"os"
	"reflect"
	"runtime"
	"slices"
	"sort"
	"strings"
	"sync"
	"testing"
	"time"
)

// oneGaussian: mean (0, 0, 0, 0.5), covariance diag(1, 1, 1, 0.5) with
// cov(x, gray) = 0.2.
func oneGaussian(t *testing.T) *Model {
	t.Helper()
	cov := make([]float32, 16)
	cov[0], cov[5], cov[10], cov[15] = 1, 1, 1, 0.5
	cov[3], cov[12] = 0.2, 0.2
	m, err := FromArrays([]float32{1}, []float32{0, 0, 0, 0.5}, cov, 10)
	return held(t, m, err)
}

// twoBlobs: deterministic points around x = -1 (gray 0.2) and x = +1 (gray 0.8).
func twoBlobs(n int) []float32 {
	s := uint64(12345)
	next := func() float32 {
		s = s*6364136223846793005 + 1442695040888963407
		return float32(s>>40)/float32(1<<24) - 0.5
	}
	pts := make([]float32, 0, 4*n)
	for i := 0; i < n; i++ {
		cx, g := float32(-1), float32(0.2)
		if i%2 == 1 {
			cx, g = 1, 0.8
		}
		pts = append(pts, cx+0.1*next(), 0.1*next(), 2+0.1*next(), g+0.01*next())
	}
	return pts
}

func TestArraysRoundTrip(t *testing.T) {
	m := oneGaussian(t)
	w, _ := m.Weights()
	mu, _ := m.Means()
	cov, _ := m.Covariances()
	if !slices.Equal(w, []float32{1}) || !slices.Equal(mu, []float32{0, 0, 0, 0.5}) || cov[3] != 0.2 {
		t.Fatalf("got %v %v %v", w, mu, cov)
	}
	if s, err := m.InfoI64(InfoSupportSize); err != nil || s != 10 {
		t.Fatalf("support %d %v", s, err)
	}
	if _, err := m.InfoI64(InfoFitIterations); !errors.Is(err, ErrNotFound) {
		t.Fatalf("fit report of an array model: %v", err)
	}
}

func TestRegressionAndScoreClosedForm(t *testing.T) {
	m := oneGaussian(t)
	// Both points are within 2.3 sigma: far out (beyond ~6.5 sigma) the answer
	// blends towards the prior on purpose (sogmm.h, sogmm_model_regress_gray).
	mean, v, err := m.RegressGray(context.Background(), []float32{1, 0, 0, -2, 0.5, 1}, nil)
	if err != nil {
		t.Fatal(err)
	}
	// Gaussian conditioning: mean = 0.5 + 0.2 x, variance = 0.5 - 0.2^2.
	if math.Abs(float64(mean[0])-0.7) > 1e-6 || math.Abs(float64(mean[1])-0.1) > 1e-6 ||
		math.Abs(float64(v[0])-0.46) > 1e-6 || math.Abs(float64(v[1])-0.46) > 1e-6 {
		t.Fatalf("mean %v variance %v", mean, v)
	}
	got, err := m.ScoreSamples(context.Background(), []float32{0, 0, 0, 0.5}, 4, nil)
	if err != nil {
		t.Fatal(err)
	}
	want := -0.5 * (4*math.Log(2*math.Pi) + math.Log(0.46))
	if math.Abs(got[0]-want) > 1e-5 {
		t.Fatalf("score %v want %v", got, want)
	}
}

func TestFixedKFit(t *testing.T) {
	o := mustOptions(t, Seed(7), Threads(1), NComponents(2))
	m := mustFit(t, twoBlobs(400), o)
	mu, _ := m.Means()
	xs := [][2]float32{{mu[0], mu[3]}, {mu[4], mu[7]}}
	sort.Slice(xs, func(i, j int) bool { return xs[i][0] < xs[j][0] })
	if math.Abs(float64(xs[0][0]+1)) > 0.05 || math.Abs(float64(xs[0][1]-0.2)) > 0.01 ||
		math.Abs(float64(xs[1][0]-1)) > 0.05 || math.Abs(float64(xs[1][1]-0.8)) > 0.01 {
		t.Fatalf("means %v", xs)
	}
	if s, _ := m.InfoI64(InfoFitSeed); s != 7 {
		t.Fatalf("seed %d", s)
	}
}

func TestRegCovarAutoFollowsTheDataScale(t *testing.T) {
	o := mustOptions(t, Seed(1), Threads(1), NComponents(2))
	if v, _ := o.GetF64(OptRegCovar); v != RegCovarAuto {
		t.Fatalf("default reg_covar %v, want RegCovarAuto", v)
	}
	floor := func(scale float32) float64 {
		pts := twoBlobs(400)
		for i := 0; i < len(pts); i += 4 {
			pts[i], pts[i+1], pts[i+2] = scale*pts[i], scale*pts[i+1], scale*pts[i+2]
		}
		m := mustFit(t, pts, o)
		f, err := m.InfoF64(InfoFitRegCovar)
		if err != nil {
			t.Fatal(err)
		}
		return f
	}
	// twoBlobs' median distance from the median is about 0.11 (10^-1: 1e-8);
	// a thousand times larger, 10^2: 1e-2, 100^3 times the first.
	small, large := floor(1), floor(1000)
	if small != 1e-8 || large != 1e-2 {
		t.Fatalf("automatic spatial floors %v and %v, want 1e-8 and 1e-2", small, large)
	}
	// A value replaces the automatic floors; RegCovarAuto restores them.
	if err := o.Set(RegCovar(1e-3)); err != nil {
		t.Fatal(err)
	}
	if f := floor(1000); f != 1e-3 {
		t.Fatalf("user floor recorded as %v", f)
	}
	if err := o.Set(RegCovar(RegCovarAuto)); err != nil {
		t.Fatal(err)
	}
	if f := floor(1000); f != 1e-2 {
		t.Fatalf("restored automatic floor %v", f)
	}
	if err := o.Set(RegCovar(-2)); !errors.Is(err, ErrInvalidArg) {
		t.Fatalf("reg_covar -2: %v", err)
	}
}

func TestSeedsAreReproducible(t *testing.T) {
	o, _ := NewOptions(Bandwidth(0.5), Seed(3), Threads(1))
	defer o.Close()
	a := mustFit(t, twoBlobs(200), o)
	b, _ := Fit(context.Background(), twoBlobs(200), o)
	defer b.Close()
	ma, _ := a.Means()
	mb, _ := b.Means()
	sa, _ := a.Sample(context.Background(), 100, 9, 4, nil)
	sb, _ := b.Sample(context.Background(), 100, 9, 4, nil)
	sc, _ := a.Sample(context.Background(), 100, 10, 4, nil)
	if !slices.Equal(ma, mb) || !slices.Equal(sa, sb) || slices.Equal(sa, sc) {
		t.Fatal("same seed must give the same fit and samples, another seed other samples")
	}
}

func TestErrorsWorkWithErrorsIs(t *testing.T) {
	_, err := Fit(context.Background(), []float32{float32(math.NaN()), 0, 0, 0}, nil)
	var e *Error
	if !errors.Is(err, ErrInvalidData) || !errors.As(err, &e) || e.Message == "" || errors.Is(err, ErrInvalidArg) {
		t.Fatalf("NaN fit: %v", err)
	}
	_, err = NewOptions(Bandwidth(-1))
	if !errors.Is(err, ErrInvalidArg) || !strings.Contains(strings.ToLower(err.Error()), "bandwidth") {
		t.Fatalf("bad bandwidth: %v", err)
	}
	if _, err = Fit(context.Background(), make([]float32, 5), nil); !errors.Is(err, ErrInvalidArg) {
		t.Fatalf("ragged points: %v", err)
	}
	if _, err = FromBytes([]byte("not a model"), nil); !errors.Is(err, ErrFormat) {
		t.Fatalf("garbage bytes: %v", err)
	}
	if _, err = FromBytes(nil, nil); !errors.Is(err, ErrFormat) {
		t.Fatalf("no bytes: %v", err)
	}
	if _, err = Load("/nonexistent/dir/x.sogmm", nil); !errors.Is(err, ErrIO) {
		t.Fatalf("missing file: %v", err)
	}
	m := oneGaussian(t)
	if _, err = m.Sample(context.Background(), 1, 0, 5, nil); !errors.Is(err, ErrInvalidArg) {
		t.Fatalf("dims 5: %v", err)
	}
	if _, err = m.Sample(context.Background(), math.MaxInt/2, 0, 4, nil); !errors.Is(err, ErrLimit) {
		t.Fatalf("huge n: %v", err)
	}
}

func TestBytesFilesMetadata(t *testing.T) {
	m := oneGaussian(t)
	if err := m.SetValue("origin", "go test"); err != nil {
		t.Fatal(err)
	}
	pose := [16]float64{1, 0, 0, 1, 0, 1, 0, 2, 0, 0, 1, 3, 0, 0, 0, 1}
	if err := m.SetPose(pose); err != nil {
		t.Fatal(err)
	}
	o, _ := NewOptions(ZstdLevel(1))
	defer o.Close()
	raw, err := m.Bytes(o)
	if err != nil {
		t.Fatal(err)
	}
	back, err := FromBytes(raw, nil)
	if err != nil {
		t.Fatal(err)
	}
	defer back.Close()
	if v, _ := back.Value("origin"); v != "go test" {
		t.Fatalf("value %q", v)
	}
	if _, err := back.Value("absent"); !errors.Is(err, ErrNotFound) {
		t.Fatalf("absent key: %v", err)
	}
	if p, _ := back.Pose(); p != pose {
		t.Fatalf("pose %v", p)
	}
	path := savedFile(t, m, "m.sogmm")
	loaded := mustLoad(t, path)
	c1, _ := m.Covariances()
	c2, _ := loaded.Covariances()
	vs, _ := loaded.Values()
	if !slices.Equal(c1, c2) || len(vs) != 1 || vs[0] != [2]string{"origin", "go test"} {
		t.Fatalf("file round trip: %v %v %v", c1, c2, vs)
	}
	if _, err := os.Stat(path); err != nil {
		t.Fatal(err)
	}
}

func TestCloneMergeTransform(t *testing.T) {
	a := oneGaussian(t)
	b, err := a.Clone()
	if err != nil {
		t.Fatal(err)
	}
	defer b.Close()
	_ = b.SetValue("k", "v")
	if _, err := a.Value("k"); !errors.Is(err, ErrNotFound) {
		t.Fatal("clone is not deep")
	}
	ab, err := a.Merge(b)
	if err != nil {
		t.Fatal(err)
	}
	defer ab.Close()
	if w, _ := ab.Weights(); !slices.Equal(w, []float32{0.5, 0.5}) {
		t.Fatalf("merged weights %v", w)
	}
	moved, err := a.Transform([16]float64{1, 0, 0, 1, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1})
	if err != nil {
		t.Fatal(err)
	}
	defer moved.Close()
	if mu, _ := moved.Means(); !slices.Equal(mu, []float32{1, 0, 0, 0.5}) {
		t.Fatalf("moved means %v", mu)
	}
}

func TestRGBDChecksSliceLengths(t *testing.T) {
	const w, h = 32, 24
	depth := make([]uint16, w*h)
	gray := make([]uint8, w*h)
	for i := range depth {
		depth[i] = uint16(1000 + (i%w)*10)
		if i%w >= w/2 {
			gray[i] = 200
		}
	}
	f := Frame{Depth: depth, Gray8: gray, Width: w, Height: h, Fx: 30, Fy: 30, Cx: 15.5, Cy: 11.5}
	o, _ := NewOptions(Bandwidth(0.1), Threads(1))
	defer o.Close()
	m, err := FitRGBD(context.Background(), f, o)
	if err != nil {
		t.Fatal(err)
	}
	defer m.Close()
	if cw, _ := m.InfoI64(InfoCameraWidth); cw != w {
		t.Fatalf("camera width %d", cw)
	}
	short := f
	short.Depth = depth[1:]
	if _, err := FitRGBD(context.Background(), short, nil); !errors.Is(err, ErrInvalidArg) {
		t.Fatalf("short depth: %v", err)
	}
	both := f
	both.RGB8 = gray
	if _, err := FitRGBD(context.Background(), both, nil); !errors.Is(err, ErrInvalidArg) {
		t.Fatalf("two color images: %v", err)
	}
}

func TestCloseIsIdempotentAndFinalizerFrees(t *testing.T) {
	m := oneGaussian(t)
	m.Close()
	m.Close()
	if _, err := m.Weights(); !errors.Is(err, ErrClosed) {
		t.Fatalf("use after close: %v", err)
	}
	before := finalizerRuns.get()
	func() {
		for i := 0; i < 8; i++ {
			if _, err := FromArrays([]float32{1}, []float32{0, 0, 0, 0}, identity16(), 0); err != nil {
				t.Fatal(err)
			}
		}
	}()
	deadline := time.Now().Add(10 * time.Second)
	for finalizerRuns.get()-before < 8 && time.Now().Before(deadline) {
		runtime.GC()
		time.Sleep(10 * time.Millisecond)
	}
	if got := finalizerRuns.get() - before; got < 8 {
		t.Fatalf("finalizer freed %d of 8 dropped models", got)
	}
}

func identity16() []float32 {
	return []float32{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}
}

// Concurrent const use of one model (run under -race) gives the serial results,
// and each goroutine sees its own error message.
func TestSharedModelAcrossGoroutines(t *testing.T) {
	m := oneGaussian(t)
	serial := make([][]float32, 8)
	for s := range serial {
		serial[s], _ = m.Sample(context.Background(), 300, uint64(s), 4, nil)
	}
	var wg sync.WaitGroup
	errs := make(chan error, 16)
	for s := 0; s < 8; s++ {
		wg.Add(2)
		go func(s int) {
			defer wg.Done()
			got, err := m.Sample(context.Background(), 300, uint64(s), 4, nil)
			if err != nil || !slices.Equal(got, serial[s]) {
				errs <- errors.New("concurrent sample differs from the serial one")
			}
		}(s)
		go func() {
			defer wg.Done()
			bad, err := Fit(context.Background(), []float32{float32(math.Inf(1)), 0, 0, 0}, nil)
			if bad != nil {
				bad.Close()
			}
			var e *Error
			if !errors.As(err, &e) || e.Status != ErrInvalidData || e.Message == "" {
				errs <- fmt.Errorf("wrong error: %v", err)
			}
		}()
	}
	wg.Wait()
	close(errs)
	for err := range errs {
		t.Error(err)
	}
}

func TestOptionsCloneAndGet(t *testing.T) {
	o := mustOptions(t, Seed(math.MaxUint64), ZstdLevel(3))
	if s, _ := o.GetI64(OptSeed); s != -1 {
		t.Fatalf("seed bits %d", s)
	}
	c, _ := o.Clone()
	defer c.Close()
	_ = o.SetI64(OptZstdLevel, 5)
	if l, _ := c.GetI64(OptZstdLevel); l != 3 {
		t.Fatal("options clone is not deep")
	}
	if _, err := o.GetF64(OptSeed); !errors.Is(err, ErrInvalidArg) {
		t.Fatalf("wrong type: %v", err)
	}
	if Version() == "" {
		t.Fatal("no version")
	}
}

func TestFramePointsByHand(t *testing.T) {
	// 2 x 2 frame, fx = fy = 2, cx = cy = 0.5: x = (u - 0.5) z / 2, y = (v - 0.5) z / 2.
	f := Frame{Depth: []uint16{1000, 2000, 0, 1000}, Gray8: []uint8{0, 255, 7, 51}, Width: 2, Height: 2,
		Fx: 2, Fy: 2, Cx: 0.5, Cy: 0.5}
	got, err := f.Points(nil)
	if err != nil {
		t.Fatal(err)
	}
	want := []float32{-0.25, -0.25, 1, 0, 0.5, -0.5, 2, 1, 0.25, 0.25, 1, 0.2}
	if len(got) != len(want) {
		t.Fatalf("got %v", got)
	}
	for i := range want {
		if math.Abs(float64(got[i]-want[i])) > 1e-6 {
			t.Fatalf("got %v want %v", got, want)
		}
	}
	f.Depth = []uint16{0, 0, 0, 0}
	if none, err := f.Points(nil); err != nil || len(none) != 0 {
		t.Fatalf("no valid pixel: %v %v", none, err)
	}
}

// staircaseFrame: 8 fronto-parallel steps 10 cm apart, so the depth sits on
// exact levels and the depth-quantisation floor changes the fit.
func staircaseFrame() Frame {
	const w, h = 96, 72
	f := Frame{Width: w, Height: h, Fx: 77, Fy: 77, Cx: (w - 1) / 2.0, Cy: (h - 1) / 2.0}
	f.Depth = make([]uint16, w*h)
	f.Gray8 = make([]uint8, w*h)
	for v := 0; v < h; v++ {
		for u := 0; u < w; u++ {
			f.Depth[v*w+u] = uint16(1000 + 100*(u/12))
			f.Gray8[v*w+u] = uint8(60 + 2*u + v)
		}
	}
	return f
}

// The library's default (DequantiseAuto) floors an RGB-D frame and not the
// same points given as an array; DequantiseDepth forces either.
func TestTheDepthFloorIsTheDefaultForFrames(t *testing.T) {
	covariances := func(extra ...Option) []float32 {
		o := mustOptions(t, append([]Option{Bandwidth(0.05), Seed(3), Threads(1), Decimation(2)}, extra...)...)
		m, err := FitRGBD(context.Background(), staircaseFrame(), o)
		if err != nil {
			t.Fatal(err)
		}
		defer m.Close()
		c, err := m.Covariances()
		if err != nil {
			t.Fatal(err)
		}
		return c
	}
	o := mustOptions(t)
	if v, _ := o.GetI64(OptDequantiseDepth); v != DequantiseAuto {
		t.Fatalf("default dequantise_depth %v, want DequantiseAuto", v)
	}
	def, on, off := covariances(), covariances(DequantiseDepth(true)), covariances(DequantiseDepth(false))
	if !reflect.DeepEqual(def, on) {
		t.Fatal("the default fit of a frame differs from the floored one")
	}
	if reflect.DeepEqual(def, off) {
		t.Fatal("the floor changed nothing: the test would be vacuous")
	}
	if err := o.Set(I64(OptDequantiseDepth, -2)); !errors.Is(err, ErrInvalidArg) {
		t.Fatalf("dequantise_depth -2: %v", err)
	}
}
