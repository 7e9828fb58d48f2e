package sogmm

import (
	"bytes"
	"errors"
	"math"
	"os"
	"path/filepath"
	"testing"
)

// variedComponents: m components like a map's, from a fixed linear
// congruential generator: means spread over a metre, covariances
// A A^T / 100 + I / 1000 (positive definite, conditions up to ~10^3),
// weights over a decade.
func variedComponents(t *testing.T, m int) *Model {
	t.Helper()
	s := uint64(2024)
	next := func() float64 {
		s = s*6364136223846793005 + 1442695040888963407
		return float64(s>>40)/float64(1<<24) - 0.5
	}
	var w, mu, cov []float32
	for c := 0; c < m; c++ {
		w = append(w, float32(1.5+next()))
		mu = append(mu, float32(next()), float32(next()), float32(2+next()), float32(0.5+0.5*next()))
		var a [16]float64
		for i := range a {
			a[i] = next()
		}
		for i := 0; i < 4; i++ {
			for j := 0; j < 4; j++ {
				v := 0.0
				for k := 0; k < 4; k++ {
					v += a[4*i+k] * a[4*j+k]
				}
				v /= 100
				if i == j {
					v += 1e-3
				}
				cov = append(cov, float32(v))
			}
		}
	}
	total := float32(0)
	for _, v := range w {
		total += v
	}
	for i := range w {
		w[i] /= total
	}
	model, err := FromArrays(w, mu, cov, 1000)
	return held(t, model, err)
}

// sigmas is |L^-1 d| for S = L L^T (4 x 4, row-major): the distance d in
// standard deviations of the Gaussian with covariance S.
func sigmas(s []float32, d [4]float64) float64 {
	var l [16]float64
	for j := 0; j < 4; j++ {
		diag := float64(s[5*j])
		for k := 0; k < j; k++ {
			diag -= l[4*j+k] * l[4*j+k]
		}
		l[5*j] = math.Sqrt(diag)
		for i := j + 1; i < 4; i++ {
			v := float64(s[4*i+j])
			for k := 0; k < j; k++ {
				v -= l[4*i+k] * l[4*j+k]
			}
			l[4*i+j] = v / l[5*j]
		}
	}
	var x [4]float64
	sum := 0.0
	for i := 0; i < 4; i++ {
		v := d[i]
		for k := 0; k < i; k++ {
			v -= l[4*i+k] * x[k]
		}
		x[i] = v / l[5*i]
		sum += x[i] * x[i]
	}
	return math.Sqrt(sum)
}

// SOGMM_OPT_ARRAY_PRECISION (sogmm.h, spec/api.md): at precision P a saved
// component's mean moves by at most P of its own standard deviations,
// |L^-1 (mu' - mu)| <= P with S = L L^T the saved covariance. The encoder
// checks that bound on the decoded float32 values before writing; this test
// recomputes it in binary64 (its own rounding, ~1e-15 relative, is inside
// the 1e-9 allowed). Mutation tried: ArrayPrecision setting the map's key
// (OptMapComponentPrecision) leaves the file uncoded: the size and "some
// mean moved" checks fail.
func TestArrayPrecisionCodesMeansWithinTheirBound(t *testing.T) {
	m := variedComponents(t, 40)
	dir := t.TempDir()
	exactPath, codedPath := filepath.Join(dir, "exact.sogmm"), filepath.Join(dir, "coded.sogmm")
	exact := mustOptions(t, ArrayPrecision(0))
	coded := mustOptions(t, ArrayPrecision(0.5))
	if err := m.Save(exactPath, exact); err != nil {
		t.Fatal(err)
	}
	if err := m.Save(codedPath, coded); err != nil {
		t.Fatal(err)
	}
	exactBytes, _ := os.ReadFile(exactPath)
	codedBytes, _ := os.ReadFile(codedPath)
	if len(codedBytes) >= len(exactBytes) {
		t.Fatalf("coded file %d bytes, exact %d", len(codedBytes), len(exactBytes))
	}

	back, err := Load(codedPath, nil)
	held(t, back, err)
	mu0, _ := m.Means()
	s0, _ := m.Covariances()
	mu1, _ := back.Means()
	if len(mu1) != len(mu0) {
		t.Fatalf("%d means back, %d saved", len(mu1), len(mu0))
	}
	moved := 0
	for k := 0; k < len(mu0)/4; k++ {
		var d [4]float64
		for i := range d {
			d[i] = float64(mu1[4*k+i]) - float64(mu0[4*k+i])
		}
		e := sigmas(s0[16*k:16*k+16], d)
		if !(e <= 0.5*(1+1e-9)) {
			t.Fatalf("component %d: mean moved %g sigmas", k, e)
		}
		if e > 0 {
			moved++
		}
	}
	if moved == 0 {
		t.Fatal("the means were stored bit for bit, not as codes")
	}
	exactBack, err := Load(exactPath, nil)
	held(t, exactBack, err)
	if mu, _ := exactBack.Means(); !slicesEqual(mu, mu0) {
		t.Fatal("precision 0: float arrays must be bit-exact")
	}

	// Out of range: ErrInvalidArg, the options keep their value (a save with
	// them writes the same bytes again) and the file is untouched.
	for _, bad := range []float64{0.7, -1, math.NaN()} {
		if _, err := NewOptions(ArrayPrecision(bad)); !errors.Is(err, ErrInvalidArg) {
			t.Fatalf("%g: %v", bad, err)
		}
		if err := coded.Set(ArrayPrecision(bad)); !errors.Is(err, ErrInvalidArg) {
			t.Fatalf("%g: %v", bad, err)
		}
		if v, _ := coded.GetF64(OptArrayPrecision); v != 0.5 {
			t.Fatalf("%g: the options hold %g", bad, v)
		}
		if now, _ := os.ReadFile(codedPath); !bytes.Equal(now, codedBytes) {
			t.Fatalf("%g: the file changed", bad)
		}
	}
	if err := m.Save(exactPath, coded); err != nil {
		t.Fatal(err)
	}
	if again, _ := os.ReadFile(exactPath); !bytes.Equal(again, codedBytes) {
		t.Fatal("a save after the refused values differs")
	}
}

func slicesEqual(a, b []float32) bool {
	if len(a) != len(b) {
		return false
	}
	for i := range a {
		if math.Float32bits(a[i]) != math.Float32bits(b[i]) {
			return false
		}
	}
	return true
}
