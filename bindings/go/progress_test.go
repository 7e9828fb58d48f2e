package sogmm

import (
	"context"
	"errors"
	"strings"
	"testing"
)

// cube: n deterministic points uniform in a unit cube, so EM with several
// components runs many iterations.
func cube(n int) []float32 {
	s := uint64(99)
	pts := make([]float32, 4*n)
	for i := range pts {
		s = s*6364136223846793005 + 1442695040888963407
		pts[i] = float32(s>>40) / float32(1<<24)
	}
	return pts
}

func emOptions(t *testing.T) *Options {
	t.Helper()
	o, err := NewOptions(NComponents(8), Tol(1e-12), MaxIter(25), Seed(5), Threads(2))
	return held(t, o, err)
}

func TestProgressReportsEMInOrderAndChangesNothing(t *testing.T) {
	pts := cube(3000)
	var seen []Progress
	m, err := Fit(context.Background(), pts, reporting(emOptions(t), func(p Progress) error {
		seen = append(seen, p)
		return nil
	}))
	if err != nil {
		t.Fatal(err)
	}
	defer m.Close()
	plain := mustFit(t, pts, emOptions(t))
	a, _ := m.Means()
	b, _ := plain.Means()
	if len(a) != len(b) || len(a) == 0 {
		t.Fatalf("means: %d vs %d", len(a), len(b))
	}
	for i := range a {
		if a[i] != b[i] {
			t.Fatalf("progress changed the model at %d", i)
		}
	}
	iters, _ := m.InfoI64(InfoFitIterations)
	if seen[0].Stage != StageSeeding || seen[len(seen)-1].Stage != StageEM {
		t.Fatalf("stages: first %v last %v", seen[0].Stage, seen[len(seen)-1].Stage)
	}
	next := uint64(0) // EM steps 0, 1, ..., iters, each at least once, never decreasing
	for _, p := range seen {
		if p.Stage != StageEM {
			continue
		}
		if p.Total != 25 || p.Step > next || (p.Step < next && p.Step != next-1) {
			t.Fatalf("EM report %+v after step %d", p, next)
		}
		if p.Step == next {
			next++
		}
	}
	if next != uint64(iters)+1 {
		t.Fatalf("EM steps reported up to %d, fit ran %d iterations", next-1, iters)
	}
}

func TestProgressErrorCancelsWithNoModel(t *testing.T) {
	stop := errors.New("stop at EM 2")
	m, err := Fit(context.Background(), cube(3000), reporting(emOptions(t), func(p Progress) error {
		if p.Stage == StageEM && p.Step == 2 {
			return stop
		}
		return nil
	}))
	if m != nil {
		t.Fatal("a cancelled fit returned a model")
	}
	if !errors.Is(err, ErrCancelled) || !errors.Is(err, stop) {
		t.Fatalf("want ErrCancelled wrapping the callback's error, got %v", err)
	}
	if !strings.Contains(err.Error(), "EM iteration 2") {
		t.Fatalf("message does not name the stage: %v", err)
	}
}

func TestCancelledContextStopsTheFit(t *testing.T) {
	ctx, cancel := context.WithCancel(context.Background())
	reports := 0
	m, err := Fit(ctx, cube(3000), reporting(emOptions(t), func(p Progress) error {
		reports++
		if p.Stage == StageEM && p.Step == 1 {
			cancel() // as another goroutine would; seen at the next report
		}
		return nil
	}))
	if m != nil || !errors.Is(err, ErrCancelled) || !errors.Is(err, context.Canceled) {
		t.Fatalf("want ErrCancelled and context.Canceled, got model %v, err %v", m, err)
	}
	// A context done before the call: nothing runs past the first report.
	m, err = Fit(ctx, cube(3000), emOptions(t))
	if m != nil || !errors.Is(err, context.Canceled) {
		t.Fatalf("done context: got %v, %v", m, err)
	}
}

func TestPanicInProgressIsRaisedAfterTheCall(t *testing.T) {
	calls := 0
	defer func() {
		if r := recover(); r != "boom" {
			t.Fatalf("recovered %v", r)
		}
		if calls != 1 {
			t.Fatalf("callback called %d times after panicking", calls)
		}
	}()
	_, _ = Fit(context.Background(), cube(3000), reporting(emOptions(t), func(p Progress) error {
		if p.Stage == StageEM {
			calls++
			panic("boom")
		}
		return nil
	}))
	t.Fatal("no panic")
}
