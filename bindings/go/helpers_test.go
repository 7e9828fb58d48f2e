package sogmm

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
