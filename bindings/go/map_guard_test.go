package sogmm

import (
	"context"
	"errors"
	"strings"
	"sync"
	"testing"
)

// A map whose first insert of twoBlobs(400) runs a fit (so it reports).
func guardedMap(t *testing.T) (*Map, *Options) {
	o, err := NewOptions(Bandwidth(0.3), Seed(2), Threads(1), I64(OptMapBatchSize, 200))
	if err != nil {
		t.Fatal(err)
	}
	m, err := NewMap(o)
	if err != nil {
		t.Fatal(err)
	}
	return m, o
}

func isBusy(err error) bool {
	var e *Error
	return errors.Is(err, ErrBusy) && errors.As(err, &e) && strings.HasPrefix(e.Message, "map busy: ")
}

// expectAllBusy reports each of errs (what: which calls) that is not a
// "map busy" ErrBusy.
func expectAllBusy(t *testing.T, errs []error, what string) {
	t.Helper()
	for k, e := range errs {
		if !isBusy(e) {
			t.Errorf("%s %d: %v, want map busy", what, k, e)
		}
	}
}

// The map's own progress func calling into it gets ErrBusy, Close from it
// leaves the map open, and the insert goes on (issue 36).
func TestMapCallsFromItsProgressFuncAreBusy(t *testing.T) {
	m, o := guardedMap(t)
	defer o.Close()
	defer m.Close()
	pts := twoBlobs(400)
	var nested []error
	err := setProgress(m, func(Progress) error {
		if nested == nil {
			nested = append(nested, m.InsertPoints(context.Background(), pts, yawPose(0, 0, 0, 0)), m.Flush(context.Background()))
			_, err := m.Stats()
			nested = append(nested, err)
			m.Close() // does nothing: the map is in use
		}
		return nil
	}).InsertPoints(context.Background(), pts, yawPose(0, 0, 0, 0))
	if err != nil {
		t.Fatal(err)
	}
	expectAllBusy(t, nested, "nested call")
	s, err := m.Stats() // still open
	if err != nil || s.Frames != 1 || s.Flushes != 1 {
		t.Fatalf("after the insert: %+v, %v", s, err)
	}
}

// A second goroutine's calls while an insert runs get ErrBusy; the two meet
// inside the insert's progress func, so the overlap is certain.
func TestMapCallsFromAnotherGoroutineAreBusy(t *testing.T) {
	m, o := guardedMap(t)
	defer o.Close()
	defer m.Close()
	pts := twoBlobs(400)
	inside, tried := make(chan struct{}), make(chan struct{})
	var once sync.Once
	var errs []error
	go func() {
		<-inside
		_, e1 := m.Stats()
		_, e2 := m.Export(nil)
		errs = []error{m.InsertPoints(context.Background(), pts, yawPose(0, 0, 0, 0)), e1, e2}
		m.Close()
		close(tried)
	}()
	err := setProgress(m, func(Progress) error {
		once.Do(func() { close(inside); <-tried })
		return nil
	}).InsertPoints(context.Background(), pts, yawPose(0, 0, 0, 0))
	if err != nil {
		t.Fatal(err)
	}
	expectAllBusy(t, errs, "call of the other goroutine")
	if s, err := m.Stats(); err != nil || s.Frames != 1 {
		t.Fatalf("after the insert: %+v, %v", s, err)
	}
}
