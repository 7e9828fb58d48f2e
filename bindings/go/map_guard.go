package sogmm

// #include "sogmm/sogmm.h"
import "C"

import (
	"context"
	"sync"
)

// mapGuard is the Go side of the map's use guard (sogmm.h, "Use guard"): a
// call changing the map (InsertPoints, InsertRGBD, Flush, Close) needs it alone, reading calls share it, and a call that finds
// it otherwise taken fails at once with ErrBusy ("map busy: ..."), never
// waits (a progress func calling into its own map would deadlock). The C
// library checks the same inside its calls; this also covers what Go does
// around them: the handle Close frees, and the progress callback an insert
// installs and removes.
type mapGuard struct {
	mu    sync.Mutex
	users int // > 0: reading calls; -1: the one changing call
}

func (g *mapGuard) take(change bool, what string) error {
	g.mu.Lock()
	defer g.mu.Unlock()
	if change && g.users != 0 {
		return busy(what, "another call is using the map")
	}
	if !change && g.users < 0 {
		return busy(what, "a call changing the map runs")
	}
	if change {
		g.users = -1
	} else {
		g.users++
	}
	return nil
}

func (g *mapGuard) release(change bool) {
	g.mu.Lock()
	defer g.mu.Unlock()
	if change {
		g.users = 0
	} else {
		g.users--
	}
}

func busy(what, conflict string) error {
	return &Error{Status: ErrBusy, Message: "map busy: Map." + what + " cannot run while " + conflict +
		" (on another goroutine, or the call whose progress func is running); a map is changed by one call at a time"}
}

// change runs f on m's handle holding m alone; when ctx can be cancelled or
// the map has a progress func, the callback is installed for f and removed
// after it (withMapProgress).
func (m *Map) change(ctx context.Context, what string, f func(p *C.sogmm_map) C.sogmm_status) error {
	if m == nil {
		return ErrClosed
	}
	if ctx == nil {
		return invalidArg("nil context (pass context.Background())")
	}
	if err := m.guard.take(true, what); err != nil {
		return err
	}
	defer m.guard.release(true)
	if ctx.Done() != nil || m.progress != nil {
		return withMapProgress(ctx, m, f)
	}
	return m.doWith(nil, func(h *C.sogmm_map, _ *C.sogmm_options) C.sogmm_status { return f(h) })
}

// read runs f holding m shared with other reading calls.
func (m *Map) read(what string, f func() error) error {
	if m == nil {
		return ErrClosed
	}
	if err := m.guard.take(false, what); err != nil {
		return err
	}
	defer m.guard.release(false)
	return f()
}
