package sogmm

import (
	"errors"
	"testing"
)

// threeOverlappingClusters gives 3000 points of three overlapping clusters
// along x (a fixed linear congruential generator), where plain EM creeps to
// its fixed point.
func threeOverlappingClusters() []float32 {
	s := uint64(35)
	next := func() float32 {
		s = s*6364136223846793005 + 1442695040888963407
		return float32(s>>40)/float32(1<<24) - 0.5 // [-0.5, 0.5)
	}
	pts := make([]float32, 0, 4*3000)
	for i := 0; i < 3000; i++ {
		k := float32(i % 3)
		pts = append(pts, 0.8*k+1.5*next(), 0.5*next(), 1.0+0.3*next(), 0.3+0.3*next())
	}
	return pts
}

// SQUAREM (Squarem(true), OptEmAcceleration) reaches plain EM's fixed point
// on three overlapping clusters in fewer passes, no lower; a value outside
// 0..1 is refused.
func TestSquaremReachesTheFixedPointInFewerPasses(t *testing.T) {
	pts := threeOverlappingClusters()
	fit := func(on bool) (int64, float64) {
		o := mustOptions(t, NComponents(3), Seed(1), Threads(1), Tol(1e-7), MaxIter(3000), Squarem(on))
		m := mustFit(t, pts, o)
		it, err := m.InfoI64(InfoFitIterations)
		if err != nil {
			t.Fatal(err)
		}
		ll, err := m.InfoF64(InfoFitLogLik)
		if err != nil {
			t.Fatal(err)
		}
		return it, ll
	}
	plainIt, plainLL := fit(false)
	fastIt, fastLL := fit(true)
	if fastIt >= plainIt || fastLL < plainLL-1e-5 {
		t.Fatalf("squarem %d passes, LL %v; plain %d passes, LL %v", fastIt, fastLL, plainIt, plainLL)
	}
	o := mustOptions(t)
	if v, _ := o.GetI64(OptEmAcceleration); v != 0 {
		t.Fatalf("default em_acceleration %v, want 0", v)
	}
	if err := o.Set(I64(OptEmAcceleration, 2)); !errors.Is(err, ErrInvalidArg) {
		t.Fatalf("em_acceleration 2: %v", err)
	}
}

// TolStandardErrors(c) (OptTolStandardErrors) reaches the fit: on
// threeOverlappingClusters plain EM creeps for hundreds of passes at Tol 1e-7, far
// below one standard error of the mean log-likelihood, so c = 1 stops it
// sooner; c = 0 is the default and the fit itself; a negative c is refused.
// Mutation tried: the setter writing OptTol instead (c = 0 then sets Tol 0:
// the "same as default" check fails).
func TestTolStandardErrorsStopsTheCreep(t *testing.T) {
	pts := threeOverlappingClusters()
	fit := func(extra ...Option) int64 {
		o := mustOptions(t, append([]Option{NComponents(3), Seed(1), Threads(1), Tol(1e-7), MaxIter(3000)}, extra...)...)
		it, err := mustFit(t, pts, o).InfoI64(InfoFitIterations)
		if err != nil {
			t.Fatal(err)
		}
		return it
	}
	plain, zero, noise := fit(), fit(TolStandardErrors(0)), fit(TolStandardErrors(1))
	if zero != plain || noise >= plain {
		t.Fatalf("passes: default %d, c = 0 %d, c = 1 %d", plain, zero, noise)
	}
	if _, err := NewOptions(TolStandardErrors(-0.5)); !errors.Is(err, ErrInvalidArg) {
		t.Fatalf("c = -0.5: %v", err)
	}
}
