package sogmm

import (
	"context"
	"errors"
	"math"
	"testing"
)

// cornerArrays are flat components tiling the unit squares of the planes
// x = 0, y = 0, z = 0.
func cornerArrays() (w, mu, cov []float32) {
	for axis := 0; axis < 3; axis++ {
		for a := 0; a < 5; a++ {
			for b := 0; b < 5; b++ {
				u, v := (axis+1)%3, (axis+2)%3
				m := make([]float32, 4)
				m[u], m[v], m[3] = 0.1+0.2*float32(a), 0.1+0.2*float32(b), 0.5
				c := make([]float32, 16)
				c[5*u], c[5*v], c[5*axis], c[15] = 0.08*0.08, 0.08*0.08, 0.003*0.003, 0.01
				w = append(w, 1.0/75)
				mu = append(mu, m...)
				cov = append(cov, c...)
			}
		}
	}
	return w, mu, cov
}

// Points sampled from a corner of three planes and moved by -t register back
// to the translation t; a NaN initial pose is ErrInvalidArg.
func TestRegisterPointsRecoversATranslation(t *testing.T) {
	w, mu, cov := cornerArrays()
	model, err := FromArrays(w, mu, cov, 1)
	if err != nil {
		t.Fatal(err)
	}
	defer model.Close()
	shift := []float32{0.02, -0.01, 0.03}
	pts, err := model.Sample(context.Background(), 3000, 1, 4, nil)
	if err != nil {
		t.Fatal(err)
	}
	for i := 0; i < len(pts); i += 4 {
		for k := 0; k < 3; k++ {
			pts[i+k] -= shift[k]
		}
	}
	r, err := model.RegisterPoints(context.Background(), pts, nil, nil)
	if err != nil {
		t.Fatal(err)
	}
	if r.Status != RegistrationConverged || r.Unobservable != 0 || r.InlierRatio < 0.95 {
		t.Fatalf("status %d, unobservable %d, inliers %g", r.Status, r.Unobservable, r.InlierRatio)
	}
	// Noise: 3 mm / sqrt(1000) per plane normal, far below 1 mm.
	for k := 0; k < 3; k++ {
		if math.Abs(r.Pose[4*k+3]-float64(shift[k])) > 1e-3 || math.Abs(r.Pose[5*k]-1) > 1e-4 {
			t.Fatalf("pose %v", r.Pose)
		}
	}
	nan := [16]float64{1, 0, 0, math.NaN(), 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}
	if _, err := model.RegisterPoints(context.Background(), pts, &nan, nil); !errors.Is(err, ErrInvalidArg) {
		t.Fatalf("NaN init: %v", err)
	}
}

// The corner model moved by -t registers back to t model to model (D2D; the
// optimum of a model against its own moved copy, up to the copy's float
// rounding); a source standing for one point is ErrInvalidData.
func TestRegisterModelRecoversATranslation(t *testing.T) {
	w, mu, cov := cornerArrays()
	model, err := FromArrays(w, mu, cov, 30000)
	if err != nil {
		t.Fatal(err)
	}
	defer model.Close()
	shift := [3]float64{0.02, -0.01, 0.03}
	moved, err := model.Transform([16]float64{1, 0, 0, -shift[0], 0, 1, 0, -shift[1], 0, 0, 1, -shift[2], 0, 0, 0, 1})
	if err != nil {
		t.Fatal(err)
	}
	defer moved.Close()
	r, err := model.RegisterModel(context.Background(), moved, nil, nil)
	if err != nil {
		t.Fatal(err)
	}
	if r.Status != RegistrationConverged || r.Unobservable != 0 || r.InlierRatio < 0.95 {
		t.Fatalf("status %d, unobservable %d, inliers %g", r.Status, r.Unobservable, r.InlierRatio)
	}
	for k := 0; k < 3; k++ {
		if math.Abs(r.Pose[4*k+3]-shift[k]) > 1e-4 || math.Abs(r.Pose[5*k]-1) > 1e-6 {
			t.Fatalf("pose %v", r.Pose)
		}
	}
	one, err := FromArrays(w, mu, cov, 1)
	if err != nil {
		t.Fatal(err)
	}
	defer one.Close()
	if _, err := model.RegisterModel(context.Background(), one, nil, nil); !errors.Is(err, ErrInvalidData) {
		t.Fatalf("a source standing for one point: %v", err)
	}
}
