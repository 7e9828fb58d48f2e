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

// REGISTRATION_DEPTH_NOISE reaches the core through the options. The points
// are seen by a sensor 2 m before the corner (source frame = sensor frame, so
// rays cross the planes at an angle): drawn from the model itself, they score
// lower once each point's covariance is widened along its ray (the model they
// were drawn from maximises their expected log-likelihood), the pose still
// comes back, and a value above 1 per metre is ErrInvalidArg.
func TestRegisterPointsDepthNoiseIsAnOption(t *testing.T) {
	w, mu, cov := cornerArrays()
	model, err := FromArrays(w, mu, cov, 1)
	if err != nil {
		t.Fatal(err)
	}
	defer model.Close()
	pts, err := model.Sample(context.Background(), 3000, 1, 4, nil)
	if err != nil {
		t.Fatal(err)
	}
	c := []float32{0.5, 0.5, 2.0}
	init := [16]float64{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}
	for k := 0; k < 3; k++ {
		init[4*k+3] = -float64(c[k])
	}
	for i := 0; i < len(pts); i += 4 {
		for k := 0; k < 3; k++ {
			pts[i+k] += c[k]
		}
	}
	plain, err := model.RegisterPoints(context.Background(), pts, &init, nil)
	if err != nil {
		t.Fatal(err)
	}
	o, _ := NewOptions()
	defer o.Close()
	if err := o.SetF64(OptRegistrationDepthNoise, 0.002); err != nil {
		t.Fatal(err)
	}
	noisy, err := model.RegisterPoints(context.Background(), pts, &init, o)
	if err != nil {
		t.Fatal(err)
	}
	if noisy.Status != RegistrationConverged || !(noisy.LogLikelihood < plain.LogLikelihood) {
		t.Fatalf("status %d, log-likelihood %g with noise against %g without", noisy.Status, noisy.LogLikelihood,
			plain.LogLikelihood)
	}
	// Rays 8 mm wide at 2 m and the corner 2 m off the sensor, where a turn
	// of 1e-3 rad moves it by 2 mm: within 3 mm and 1e-3 of the truth.
	for k := 0; k < 3; k++ {
		if math.Abs(noisy.Pose[4*k+3]+float64(c[k])) > 3e-3 || math.Abs(noisy.Pose[5*k]-1) > 1e-3 {
			t.Fatalf("pose %v", noisy.Pose)
		}
	}
	if err := o.SetF64(OptRegistrationDepthNoise, 2); !errors.Is(err, ErrInvalidArg) {
		t.Fatalf("depth noise 2: %v", err)
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
