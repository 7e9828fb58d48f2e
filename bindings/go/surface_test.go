package sogmm

import (
	"context"
	"errors"
	"math"
	"testing"
)

// A map of one RGB-D frame of a plane at z = 2 m seen from the origin.
func planeMap(t *testing.T) *Map {
	t.Helper()
	m := newTestMap(t, I64(OptMapNovelty, 0), Bandwidth(0.02))
	const w, h = 64, 48
	f := Frame{Depth: make([]uint16, w*h), Gray8: make([]uint8, w*h), Width: w, Height: h, Fx: 50, Fy: 50, Cx: 31.5, Cy: 23.5}
	for i := range f.Depth {
		f.Depth[i], f.Gray8[i] = 2000, 128
	}
	if err := m.InsertRGBD(context.Background(), f, [16]float64{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}); err != nil {
		t.Fatal(err)
	}
	if err := m.Flush(context.Background()); err != nil {
		t.Fatal(err)
	}
	return m
}

func TestPlaneOccupancyDistanceCollision(t *testing.T) {
	m := planeMap(t)
	defer m.Close()
	p, s, err := m.Occupancy(context.Background(), []float32{0, 0, 1, 0, 0, 2, 0, 0, 3, 5, 0, 2}, nil)
	if err != nil {
		t.Fatal(err)
	}
	if s[0] != OccupancyFree || s[1] != OccupancyOccupied || s[2] != OccupancyUnknown || s[3] != OccupancyUnknown {
		t.Fatalf("states %v", s)
	}
	if !(p[0] < 1e-6 && p[1] > 0.9 && p[2] == 0.5 && p[3] == 0.5) {
		t.Fatalf("probabilities %v", p)
	}
	d, g, err := m.SurfaceDistance(context.Background(), []float32{0.2, -0.1, 1.7, 0.2, -0.1, 2.05}, nil)
	if err != nil {
		t.Fatal(err)
	}
	if math.Abs(d[0]-0.3) > 0.005 || math.Abs(d[1]-0.05) > 0.005 || g[2] > -0.98 || g[5] < 0.98 {
		t.Fatalf("distance %v gradient %v", d, g)
	}
	model := mustExport(t, m)
	d2, _, err := model.SurfaceDistance(context.Background(), []float32{0.2, -0.1, 1.7, 0.2, -0.1, 2.05}, nil)
	if err != nil || d2[0] != d[0] || d2[1] != d[1] {
		t.Fatalf("model distance %v (%v), map %v", d2, err, d)
	}
	sphere := []float64{0.01, 0, 0, 0, 0.01, 0, 0, 0, 0.01}
	c, err := m.CollisionProbability(context.Background(), []float64{0.1, 0.05, 2.0, 0.1, 0.05, 1.8}, append(sphere, sphere...), nil)
	if err != nil || c[0] < 0.99 || c[1] > 0.01 {
		t.Fatalf("collision %v (%v)", c, err)
	}
	if _, err := model.CollisionProbability(context.Background(), []float64{0, 0, 1}, []float64{-0.01, 0, 0, 0, -0.01, 0, 0, 0, -0.01}, nil); !errors.Is(err, ErrInvalidArg) {
		t.Fatalf("a negative radius: %v", err)
	}
	if _, _, err := m.Occupancy(context.Background(), []float32{0, float32(math.NaN()), 1}, nil); !errors.Is(err, ErrInvalidData) {
		t.Fatalf("a NaN point: %v", err)
	}
}
