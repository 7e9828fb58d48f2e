package sogmm

import (
	"context"
	"path/filepath"
	"testing"
)

// The must* helpers are set-up steps a test relies on but does not check:
// a failure stops the test at once, and the handle is closed when it ends.

// held is v once err is nil, closed when the test ends.
func held[T interface{ Close() }](t testing.TB, v T, err error) T {
	t.Helper()
	if err != nil {
		t.Fatal(err)
	}
	t.Cleanup(v.Close)
	return v
}

// mustOptions is NewOptions(opts...).
func mustOptions(t testing.TB, opts ...Option) *Options {
	t.Helper()
	o, err := NewOptions(opts...)
	return held(t, o, err)
}

// mustMap is NewMap(o).
func mustMap(t testing.TB, o *Options) *Map {
	t.Helper()
	m, err := NewMap(o)
	return held(t, m, err)
}

// mustFit is Fit(context.Background(), pts, o).
func mustFit(t testing.TB, pts []float32, o *Options) *Model {
	t.Helper()
	m, err := Fit(context.Background(), pts, o)
	return held(t, m, err)
}

// mustLoad is Load(path, nil).
func mustLoad(t testing.TB, path string) *Model {
	t.Helper()
	m, err := Load(path, nil)
	return held(t, m, err)
}

// mustLoadMap is LoadMap(path, nil).
func mustLoadMap(t testing.TB, path string) *Map {
	t.Helper()
	m, err := LoadMap(path, nil)
	return held(t, m, err)
}

// mustExport is m.Export(nil).
func mustExport(t testing.TB, m *Map) *Model {
	t.Helper()
	model, err := m.Export(nil)
	return held(t, model, err)
}

// savedFile is the path of m saved (default options) as name in a fresh
// temporary folder.
func savedFile(t testing.TB, m interface{ Save(string, *Options) error }, name string) string {
	t.Helper()
	path := filepath.Join(t.TempDir(), name)
	if err := m.Save(path, nil); err != nil {
		t.Fatal(err)
	}
	return path
}

// reporting is a copy of o (nil: defaults) whose progress func is fn, as a
// caller writes NewOptions(..., OnProgress(fn)).
func reporting(o *Options, fn ProgressFunc) *Options {
	c, err := o.copyOrDefaults()
	if err == nil {
		err = c.Set(OnProgress(fn))
	}
	if err != nil {
		panic(err)
	}
	return c
}

// setProgress gives m the progress func a map created with
// NewMap(...OnProgress(fn)) has (the tests change it between inserts).
func setProgress(m *Map, fn ProgressFunc) *Map {
	m.progress = fn
	return m
}
