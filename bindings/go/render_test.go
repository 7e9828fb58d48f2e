package sogmm

import (
	"context"
	"errors"
	"math"
	"slices"
	"testing"
)

var renderCam = Camera{Width: 9, Height: 7, Fx: 10, Fy: 12, Cx: 4, Cy: 3}

const renderCentre = 3*9 + 4

// onAxis is one component at (0, 0, 1.5), gray 0.4, gray correlated with x
// (cov 0.002): along the central ray its density peaks at t = 1.5, where
// gray = 0.4 and Var = 0.01 - 0.002^2 / 0.05^2.
func onAxis(t *testing.T) *Model {
	t.Helper()
	cov := []float32{0.0025, 0, 0, 0.002, 0, 0.0016, 0, 0, 0, 0, 0.0001, 0, 0.002, 0, 0, 0.01}
	m, err := FromArrays([]float32{1}, []float32{0, 0, 1.5, 0.4}, cov, 100)
	if err != nil {
		t.Fatal(err)
	}
	return m
}

func TestRenderSingleComponentClosedForm(t *testing.T) {
	m := onAxis(t)
	defer m.Close()
	r, err := m.Render(context.Background(), renderCam, nil, nil)
	if err != nil {
		t.Fatal(err)
	}
	if len(r.Depth) != 63 || r.Width != 9 || r.Height != 7 {
		t.Fatalf("size %d x %d, %d pixels", r.Width, r.Height, len(r.Depth))
	}
	wantVar := 0.01 - 0.002*0.002/0.0025
	if math.Abs(float64(r.Depth[renderCentre])-1.5) > 1e-5 || math.Abs(float64(r.Gray[renderCentre])-0.4) > 1e-5 ||
		math.Abs(float64(r.Variance[renderCentre])-wantVar) > 1e-6 {
		t.Fatalf("centre: depth %v gray %v variance %v", r.Depth[renderCentre], r.Gray[renderCentre], r.Variance[renderCentre])
	}
	if !math.IsNaN(float64(r.Depth[0])) || !math.IsNaN(float64(r.Gray[0])) {
		t.Fatalf("corner shows %v", r.Depth[0])
	}
	// Model and pose moved together by a yaw and a shift: the same images.
	pose := yawPose(35, 1, -2, 0.5)
	moved, err := m.Transform(pose)
	if err != nil {
		t.Fatal(err)
	}
	defer moved.Close()
	b, err := moved.Render(context.Background(), renderCam, &pose, nil)
	if err != nil {
		t.Fatal(err)
	}
	for i := range r.Depth {
		if math.IsNaN(float64(r.Depth[i])) != math.IsNaN(float64(b.Depth[i])) {
			t.Fatalf("pixel %d: %v vs %v", i, r.Depth[i], b.Depth[i])
		}
		if !math.IsNaN(float64(r.Depth[i])) && (math.Abs(float64(r.Depth[i]-b.Depth[i])) > 1e-5 ||
			math.Abs(float64(r.Gray[i]-b.Gray[i])) > 1e-5) {
			t.Fatalf("pixel %d: depth %v vs %v, gray %v vs %v", i, r.Depth[i], b.Depth[i], r.Gray[i], b.Gray[i])
		}
	}
	// Bad input.
	scaled := [16]float64{2, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}
	if _, err := m.Render(context.Background(), renderCam, &scaled, nil); !errors.Is(err, ErrInvalidArg) {
		t.Fatalf("scaled pose: %v", err)
	}
	if _, err := m.Render(context.Background(), Camera{Width: 0, Height: 7, Fx: 10, Fy: 10}, nil, nil); !errors.Is(err, ErrInvalidArg) {
		t.Fatalf("width 0: %v", err)
	}
	if _, err := m.Render(context.Background(), Camera{Width: 20000, Height: 20000, Fx: 1, Fy: 1}, nil, nil); !errors.Is(err, ErrLimit) {
		t.Fatalf("2^28 pixels: %v", err)
	}
	o := mustOptions(t, DepthRange(0.1, 1.4))
	near, err := m.Render(context.Background(), renderCam, nil, o)
	if err != nil || !math.IsNaN(float64(near.Depth[renderCentre])) {
		t.Fatalf("depth max 1.4: %v (err %v)", near.Depth[renderCentre], err)
	}
}

// Two components (weights 0.5): A at (0.025, 0, 1), isotropic sigma 0.01,
// gray 0.2; B a flat patch at (0, 0, 2) (sigma 0.1, 0.1, 0.01), gray 0.8.
// The optical axis passes A at 2.5 sigma: at z = 1 the evidence
// sum_k exp(-D_k^2 / 2) is exp(-3.125) = 0.044 (B is 100 sigma away), at
// z = 2 it is 1. Surface sigma 0 shows A at 1 m (gray 0.2); s = 2 needs
// exp(-2) = 0.135 there, so the ray passes on to B at 2 m (gray 0.8); s = 3
// needs exp(-4.5) = 0.011 and shows A again.
func TestRenderSurfaceSigmaPassesAGraze(t *testing.T) {
	cov := []float32{1e-4, 0, 0, 0, 0, 1e-4, 0, 0, 0, 0, 1e-4, 0, 0, 0, 0, 0.01,
		0.01, 0, 0, 0, 0, 0.01, 0, 0, 0, 0, 1e-4, 0, 0, 0, 0, 0.01}
	m, err := FromArrays([]float32{0.5, 0.5}, []float32{0.025, 0, 1, 0.2, 0, 0, 2, 0.8}, cov, 100)
	if err != nil {
		t.Fatal(err)
	}
	defer m.Close()
	axis := Camera{Width: 1, Height: 1, Fx: 100, Fy: 100}
	for _, c := range []struct{ s, depth, gray float64 }{{0, 1, 0.2}, {2, 2, 0.8}, {3, 1, 0.2}} {
		o, err := NewOptions(RenderSurfaceSigma(c.s))
		if err != nil {
			t.Fatal(err)
		}
		r, err := m.Render(context.Background(), axis, nil, o)
		o.Close()
		if err != nil || math.Abs(float64(r.Depth[0])-c.depth) > 1e-5 || math.Abs(float64(r.Gray[0])-c.gray) > 1e-5 {
			t.Fatalf("surface sigma %v: %+v (err %v)", c.s, r, err)
		}
	}
	if _, err := NewOptions(RenderSurfaceSigma(-1)); !errors.Is(err, ErrInvalidArg) {
		t.Fatalf("surface sigma -1: %v", err)
	}
}

// A map renders bitwise as its export; progress reports rows; a cancel is ErrCancelled.
func TestMapRenderEqualsTheExport(t *testing.T) {
	m, model := twoFrameMapAndExport(t)
	cam := Camera{Width: 40, Height: 30, Fx: 30, Fy: 30, Cx: 19.5, Cy: 14.5}
	a, err := m.Render(context.Background(), cam, nil, nil)
	if err != nil {
		t.Fatal(err)
	}
	var last Progress
	b, err := model.Render(context.Background(), cam, nil, reporting(nil, func(p Progress) error { last = p; return nil }))
	if err != nil {
		t.Fatal(err)
	}
	bits := func(v []float32) []uint32 {
		out := make([]uint32, len(v))
		for i, x := range v {
			out[i] = math.Float32bits(x)
		}
		return out
	}
	if !slices.Equal(bits(a.Depth), bits(b.Depth)) || !slices.Equal(bits(a.Gray), bits(b.Gray)) {
		t.Fatal("map render differs from its export's")
	}
	shown := 0
	for _, d := range a.Depth {
		if !math.IsNaN(float64(d)) {
			shown++
		}
	}
	if shown == 0 || last.Stage != StageRendering || last.Step != 30 || last.Total != 30 {
		t.Fatalf("%d pixels shown, last report %+v", shown, last)
	}
	ctx, cancel := context.WithCancel(context.Background())
	cancel()
	if _, err := m.Render(ctx, cam, nil, nil); !errors.Is(err, ErrCancelled) {
		t.Fatalf("cancelled render: %v", err)
	}
	empty := mustMap(t, nil)
	if _, err := empty.Render(context.Background(), cam, nil, nil); !errors.Is(err, ErrInvalidData) {
		t.Fatalf("empty map: %v", err)
	}
}
