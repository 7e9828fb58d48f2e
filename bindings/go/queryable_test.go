package sogmm

import (
	"context"
	"errors"
	"math"
	"testing"
)

// Model and Map answer through the one Queryable implementation: a map's
// answers are bitwise those of the model it exports, query by query, and a
// progress func given by the options changes no bit.
func TestQueryableModelAndMapAgree(t *testing.T) {
	m, model := twoFrameMapAndExport(t)
	ctx := context.Background()
	var reports int
	counted := reporting(nil, func(Progress) error { reports++; return nil })
	defer counted.Close()
	q := []float32{0.1, 0.2, 1.0, -0.3, 0.0, 1.2}
	robots := []float64{0.1, 0.2, 1.0}
	sphere := []float64{0.01, 0, 0, 0, 0.01, 0, 0, 0, 0.01}
	cam := Camera{Width: 16, Height: 12, Fx: 12, Fy: 12, Cx: 7.5, Cy: 5.5}
	answers := func(v Queryable, o *Options) []float64 {
		var all []float64
		s, err := v.ScoreSamples(ctx, q, 3, o)
		must(t, err)
		all = append(all, s...)
		mean, variance, err := v.RegressGray(ctx, q, o)
		must(t, err)
		all = append(all, f64s(mean)...)
		all = append(all, f64s(variance)...)
		smp, err := v.Sample(ctx, 50, 9, 4, o)
		must(t, err)
		all = append(all, f64s(smp)...)
		r, err := v.Render(ctx, cam, nil, o)
		must(t, err)
		all = append(all, f64s(r.Depth)...)
		all = append(all, f64s(r.Gray)...)
		d, g, err := v.SurfaceDistance(ctx, q, o)
		must(t, err)
		all = append(append(all, d...), g...)
		c, err := v.CollisionProbability(ctx, robots, sphere, o)
		must(t, err)
		return append(all, c...)
	}
	want := answers(model, nil)
	for name, got := range map[string][]float64{"map": answers(m, nil), "map with progress": answers(m, counted),
		"model with progress": answers(model, counted)} {
		if len(got) != len(want) {
			t.Fatalf("%s: %d answers, want %d", name, len(got), len(want))
		}
		for i := range want {
			if math.Float64bits(got[i]) != math.Float64bits(want[i]) {
				t.Fatalf("%s: answer %d is %v, want %v", name, i, got[i], want[i])
			}
		}
	}
	if reports == 0 {
		t.Fatal("the progress func of the options got no report")
	}
}

// A nil context is refused with a message, not a crash.
func TestNilContextIsRefused(t *testing.T) {
	var none context.Context // a caller's mistake, on purpose
	if _, err := Fit(none, twoBlobs(50), nil); !errors.Is(err, ErrInvalidArg) {
		t.Fatalf("nil ctx: %v", err)
	}
}

func must(t *testing.T, err error) {
	t.Helper()
	if err != nil {
		t.Fatal(err)
	}
}

func f64s(s []float32) []float64 {
	out := make([]float64, len(s))
	for i, v := range s {
		out[i] = float64(v)
	}
	return out
}
