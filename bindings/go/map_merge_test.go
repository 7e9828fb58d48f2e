package sogmm

import (
	"context"
	"errors"
	"math"
	"slices"
	"testing"
)

// MergeMap into an empty map gives the other map bitwise; bad input is
// refused and changes nothing.
func TestMergeMapIntoAnEmptyMapGivesTheOtherMap(t *testing.T) {
	other, err := NewMap(testOptions(t, Threads(1), I64(OptMapNovelty, 0)))
	if err != nil {
		t.Fatal(err)
	}
	defer other.Close()
	if err := other.InsertPoints(context.Background(), twoBlobs(200), yawPose(0, 0, 0, 0)); err != nil {
		t.Fatal(err)
	}
	m, err := NewMap(nil)
	if err != nil {
		t.Fatal(err)
	}
	defer m.Close()
	st, err := m.MergeMap(other, yawPose(0, 0, 0, 0))
	if err != nil {
		t.Fatal(err)
	}
	if st.Kept != 0 || st.Removed != 0 || st.Skipped != 0 || st.Added == 0 || st.Frames != 1 {
		t.Fatalf("stats %+v", st)
	}
	a, _ := other.Export(nil)
	b, _ := m.Export(nil)
	for _, get := range []func(*Model) ([]float32, error){(*Model).Weights, (*Model).Means, (*Model).Covariances} {
		x, _ := get(a)
		y, _ := get(b)
		if !slices.Equal(x, y) || len(x) == 0 {
			t.Fatalf("the merged map differs from the other map")
		}
	}
	if _, err := m.MergeMap(m, yawPose(0, 0, 0, 0)); !errors.Is(err, ErrInvalidArg) {
		t.Fatalf("merge into itself: got %v", err)
	}
	nan := yawPose(0, 0, 0, 0)
	nan[3] = math.NaN()
	if _, err := m.MergeMap(other, nan); !errors.Is(err, ErrInvalidArg) {
		t.Fatalf("NaN pose: got %v", err)
	}
	empty, _ := NewMap(nil)
	defer empty.Close()
	if _, err := m.MergeMap(empty, yawPose(0, 0, 0, 0)); !errors.Is(err, ErrInvalidData) {
		t.Fatalf("empty other: got %v", err)
	}
	if r, _ := m.Revision(); r != 1 {
		t.Fatalf("revision %d after refused merges, want 1", r)
	}
}
