package sogmm

import (
	"context"
	"errors"
	"slices"
	"strings"
	"testing"
)

// A receiver fed the deltas in order holds the sender's map bit for bit; a
// gap is refused and changes nothing.
func TestMapDeltasRebuildTheMapBitwiseAndRefuseAGap(t *testing.T) {
	o := testOptions(t, Threads(1), I64(OptMapNovelty, 0))
	sender := mustMap(t, o)
	receiver := mustMap(t, nil)
	var deltas [][]byte
	for k, pose := range [][16]float64{yawPose(0, 0, 0, 0), yawPose(30, 0.5, 0, -0.2)} {
		since, _ := sender.Revision()
		if err := sender.InsertPoints(context.Background(), twoBlobs(200+50*k), pose); err != nil {
			t.Fatal(err)
		}
		d, err := sender.ExportDelta(since)
		if err != nil {
			t.Fatal(err)
		}
		deltas = append(deltas, d)
	}
	if err := receiver.ApplyDelta(deltas[1]); !errors.Is(err, ErrInvalidArg) {
		t.Fatalf("a gap: got %v", err)
	}
	if r, _ := receiver.Revision(); r != 0 {
		t.Fatalf("revision %d after a refused delta", r)
	}
	for _, d := range deltas {
		if err := receiver.ApplyDelta(d); err != nil {
			t.Fatal(err)
		}
	}
	a, b := mustExport(t, sender), mustExport(t, receiver)
	for _, get := range []func(*Model) ([]float32, error){(*Model).Weights, (*Model).Means, (*Model).Covariances} {
		x, _ := get(a)
		y, _ := get(b)
		if !slices.Equal(x, y) || len(x) == 0 {
			t.Fatalf("receiver differs from sender")
		}
	}
}

// A bounded journal (OptMapDeltaHistory): with N = 1 the last revision's
// changes are exported and older ones are refused, naming the oldest kept.
func TestMapABoundedDeltaHistoryRefusesOlderRevisions(t *testing.T) {
	if _, err := NewOptions(I64(OptMapDeltaHistory, -1)); !errors.Is(err, ErrInvalidArg) {
		t.Fatalf("delta history -1: got %v", err)
	}
	m, err := NewMap(testOptions(t, Threads(1), I64(OptMapNovelty, 0), I64(OptMapDeltaHistory, 1)))
	if err != nil {
		t.Fatal(err)
	}
	defer m.Close()
	for k, pose := range [][16]float64{yawPose(0, 0, 0, 0), yawPose(30, 0.5, 0, -0.2)} {
		if err := m.InsertPoints(context.Background(), twoBlobs(200+50*k), pose); err != nil {
			t.Fatal(err)
		}
	}
	if r, _ := m.Revision(); r != 2 {
		t.Fatalf("revision %d, want 2", r)
	}
	if d, err := m.ExportDelta(1); err != nil || len(d) == 0 {
		t.Fatalf("the last revision's delta: %v", err)
	}
	_, err = m.ExportDelta(0)
	if !errors.Is(err, ErrInvalidArg) || !strings.Contains(err.Error(), "changes from revision 1") {
		t.Fatalf("a revision older than the journal: got %v", err)
	}
}
