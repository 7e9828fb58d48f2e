package sogmm

import (
	"context"
	"errors"
	"math"
	"path/filepath"
	"slices"
	"testing"
)

func yawPose(deg float64, tx, ty, tz float64) [16]float64 {
	a := deg * math.Pi / 180
	return [16]float64{math.Cos(a), 0, math.Sin(a), tx, 0, 1, 0, ty, -math.Sin(a), 0, math.Cos(a), tz, 0, 0, 0, 1}
}

// With novelty off the map is each frame's own fit moved by its pose and
// merged, component for component (computed here with Fit/Transform/Merge).
func TestMapAppendEverythingEqualsFitsMergedByHand(t *testing.T) {
	o := testOptions(t, Threads(1), I64(OptMapNovelty, 0))
	m := mustMap(t, o)
	poses := [][16]float64{yawPose(0, 0, 0, 0), yawPose(30, 0.5, 0, -0.2)}
	var want *Model
	for k, pose := range poses {
		pts := twoBlobs(200 + 50*k)
		if err := m.InsertPoints(context.Background(), pts, pose); err != nil {
			t.Fatal(err)
		}
		f, err := Fit(context.Background(), pts, o)
		if err != nil {
			t.Fatal(err)
		}
		moved, err := f.Transform(pose)
		if err != nil {
			t.Fatal(err)
		}
		if want == nil {
			want = moved
		} else if want, err = want.Merge(moved); err != nil {
			t.Fatal(err)
		}
		fs, err := m.FrameStats(uint64(k))
		if err != nil || fs.Pose != pose || fs.Novel != fs.Points || !fs.Flushed {
			t.Fatalf("frame %d stats %+v (%v)", k, fs, err)
		}
	}
	got := mustExport(t, m)
	gw, _ := got.Weights()
	ww, _ := want.Weights()
	gm, _ := got.Means()
	wm, _ := want.Means()
	if !slices.Equal(gw, ww) || !slices.Equal(gm, wm) {
		t.Fatalf("map differs from the merged fits: %d vs %d components", len(gw), len(ww))
	}
	back := mustLoadMap(t, savedFile(t, m, "map.sogmm"))
	if s, err := back.Stats(); err != nil || s.Frames != 2 || s.Components != uint64(len(gw)) {
		t.Fatalf("loaded map stats %+v (%v)", s, err)
	}
}

func TestMapRejectsBadPoseAndEmptyFrame(t *testing.T) {
	m := mustMap(t, nil)
	scaled := yawPose(0, 0, 0, 0)
	scaled[0] = 2
	if err := m.InsertPoints(context.Background(), twoBlobs(50), scaled); !errors.Is(err, ErrInvalidArg) {
		t.Fatalf("scaled pose: %v", err)
	}
	nan := yawPose(0, math.NaN(), 0, 0)
	if err := m.InsertPoints(context.Background(), twoBlobs(50), nan); !errors.Is(err, ErrInvalidArg) {
		t.Fatalf("NaN pose: %v", err)
	}
	if err := m.InsertPoints(context.Background(), nil, yawPose(0, 0, 0, 0)); !errors.Is(err, ErrInvalidData) {
		t.Fatalf("empty frame: %v", err)
	}
	if s, err := m.Stats(); err != nil || s.Frames != 0 || s.Pending != 0 {
		t.Fatalf("a failed insert changed the map: %+v (%v)", s, err)
	}
	m.Close()
	if err := m.Flush(context.Background()); !errors.Is(err, ErrClosed) {
		t.Fatalf("closed map: %v", err)
	}
}

// DiscardPending is the way out of a map whose pending points cannot be saved.
func TestMapDiscardPendingUnlocksSave(t *testing.T) {
	m := newTestMap(t, Threads(1), I64(OptMapBatchSize, 100000))
	defer m.Close()
	pts := twoBlobs(200)
	if err := m.InsertPoints(context.Background(), pts, yawPose(0, 0, 0, 0)); err != nil {
		t.Fatal(err)
	}
	path := filepath.Join(t.TempDir(), "pending.sogmm")
	if err := m.Save(path, nil); !errors.Is(err, ErrInvalidArg) {
		t.Fatalf("save with pending points: %v, want ErrInvalidArg", err)
	}
	n := uint64(len(pts) / 4)
	if got, err := m.DiscardPending(); err != nil || got != n {
		t.Fatalf("DiscardPending = %d (%v), want %d", got, err, n)
	}
	s, err := m.Stats()
	if err != nil || s.Pending != 0 || s.Frames != 1 || s.Components != 0 {
		t.Fatalf("stats after discard %+v (%v)", s, err)
	}
	if got, err := m.DiscardPending(); err != nil || got != 0 {
		t.Fatalf("second DiscardPending = %d (%v), want 0", got, err)
	}
}

// Issue 36: a map 1000 km out holds its components relative to its origin
// (the first frame's translation rounded to 1 km), finds in a mapped frame the
// novel points it finds at the world origin, and keeps the origin through save
// and load; it is declared only before the first insert.
func TestMapFarFromTheOriginKeepsItsOrigin(t *testing.T) {
	pts := twoBlobs(200)
	path := filepath.Join(t.TempDir(), "far.sogmm")
	var novel []uint64
	for _, km := range []float64{0, 1000} {
		m := newTestMap(t, Threads(1), I64(OptMapBatchSize, 100000))
		pose := yawPose(20, 1000*km+3.37, -1000*km, 0)
		if err := m.InsertPoints(context.Background(), pts, pose); err != nil {
			t.Fatal(err)
		}
		if err := m.Flush(context.Background()); err != nil {
			t.Fatal(err)
		}
		if o, err := m.Origin(); err != nil || o != [3]float64{1000 * km, -1000 * km, 0} {
			t.Fatalf("origin %v (%v) at %v km", o, err, km)
		}
		if err := m.InsertPoints(context.Background(), pts, pose); err != nil {
			t.Fatal(err)
		}
		f, err := m.FrameStats(1)
		if err != nil {
			t.Fatal(err)
		}
		novel = append(novel, f.Novel)
		if _, err := m.DiscardPending(); err != nil {
			t.Fatal(err)
		}
		if err := m.Save(path, nil); err != nil {
			t.Fatal(err)
		}
		m.Close()
	}
	if novel[1] != novel[0] {
		t.Fatalf("novel points of a mapped frame: %d at 1000 km, %d at 0 km", novel[1], novel[0])
	}
	loaded := mustLoadMap(t, path)
	if o, err := loaded.Origin(); err != nil || o != [3]float64{1e6, -1e6, 0} {
		t.Fatalf("loaded origin %v (%v)", o, err)
	}
	if err := loaded.SetOrigin([3]float64{}); !errors.Is(err, ErrInvalidArg) {
		t.Fatalf("SetOrigin after inserts: %v, want ErrInvalidArg", err)
	}
	fresh := newTestMap(t, Threads(1))
	defer fresh.Close()
	if err := fresh.SetOrigin([3]float64{math.NaN(), 0, 0}); !errors.Is(err, ErrInvalidArg) {
		t.Fatalf("SetOrigin(NaN): %v, want ErrInvalidArg", err)
	}
	if err := fresh.SetOrigin([3]float64{5e5, 0.5, 0}); err != nil {
		t.Fatal(err)
	}
	if o, err := fresh.Origin(); err != nil || o != [3]float64{5e5, 0.5, 0} {
		t.Fatalf("declared origin %v (%v)", o, err)
	}
}
