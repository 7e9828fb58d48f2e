package sogmm

/*
#include <stdint.h>
#include "sogmm/sogmm.h"
sogmm_status sogmm_go_set_progress(sogmm_options* options, uintptr_t handle);
sogmm_status sogmm_go_map_set_progress(sogmm_map* map, uintptr_t handle);
*/
import "C"

import (
	"context"
	"runtime/cgo"
)

// Stage is what a long call is doing (SOGMM_STAGE_*). The library may add
// stages; pass unknown values through.
type Stage int32

const (
	StageModeCount    Stage = C.SOGMM_STAGE_MODE_COUNT   // mean shift; Step/Total: seeds or blurring iterations
	StageSeeding      Stage = C.SOGMM_STAGE_SEEDING      // k-means++; Step/Total: components seeded / K
	StageEM           Stage = C.SOGMM_STAGE_EM           // EM; Step: iterations done (0 at start), Total: max_iter
	StageRun          Stage = C.SOGMM_STAGE_RUN          // n_init > 1: run Step (from 1) of Total starts
	StageSampling     Stage = C.SOGMM_STAGE_SAMPLING     // sampling; Step/Total: points drawn / requested
	StageScoring      Stage = C.SOGMM_STAGE_SCORING      // scoring on a map; Step/Total: points scored / requested
	StageRegression   Stage = C.SOGMM_STAGE_REGRESSION   // gray regression on a map; Step/Total: points done / requested
	StageRendering    Stage = C.SOGMM_STAGE_RENDERING    // rendering an image; Step/Total: rows done / height
	StageRegistration Stage = C.SOGMM_STAGE_REGISTRATION // registration; Step/Total: iterations done / levels x max_iter
)

// Progress is one report. Total is 0 when unknown; LogLikelihood is the mean
// per point of the last EM iteration (StageEM) or of the best run so far
// (StageRun), else 0. Reports come at each stage start, after each EM
// iteration and about every 20 ms during long loops; Step never decreases
// within a stage.
type Progress struct {
	Stage         Stage
	Step, Total   uint64
	LogLikelihood float64
}

// ProgressFunc receives reports on the goroutine that made the call, during
// the call. A non-nil error cancels: the call returns an *Error with Status
// ErrCancelled and that error as Cause, and no model.
type ProgressFunc func(Progress) error

// progressState lives for one call, behind a cgo.Handle. The library calls
// back only on the calling thread (locked by call()), one report at a time,
// so its fields need no lock.
type progressState struct {
	ctx      context.Context
	fn       ProgressFunc
	cause    error
	panicked bool
	panicVal any
}

//export sogmmGoProgress
func sogmmGoProgress(stage C.int32_t, step, total C.uint64_t, ll C.double, handle C.uintptr_t) (stop C.int32_t) {
	s := cgo.Handle(handle).Value().(*progressState)
	if s.cause != nil || s.panicked {
		return 1
	}
	// A panic must not unwind through the C++ frames: keep it and raise it
	// again once the library has returned.
	defer func() {
		if r := recover(); r != nil {
			s.panicked, s.panicVal = true, r
			stop = 1
		}
	}()
	if err := context.Cause(s.ctx); err != nil {
		s.cause = err
		return 1
	}
	if s.fn != nil {
		if err := s.fn(Progress{Stage(stage), uint64(step), uint64(total), float64(ll)}); err != nil {
			s.cause = err
			return 1
		}
	}
	return 0
}

// withProgress runs create with o, or, when ctx can be cancelled or o has
// a progress func (OnProgress), with a private copy of o (nil = defaults)
// that reports to it and watches ctx; ctx's error or the func's becomes the
// Cause of the ErrCancelled error, and a panic in the func is raised again
// here. Progress never changes a result: both paths give the same bits.
func withProgress[T any](ctx context.Context, o *Options, create func(o *Options) (T, error)) (T, error) {
	var zero T
	var fn ProgressFunc
	if o != nil {
		fn = o.progress
	}
	if ctx == nil {
		return zero, invalidArg("nil context (pass context.Background())")
	}
	if ctx.Done() == nil && fn == nil { // nothing can cancel, nobody listens
		return create(o)
	}
	private, err := o.copyOrDefaults()
	if err != nil {
		return zero, err
	}
	defer private.Close()
	state := &progressState{ctx: ctx, fn: fn}
	h := cgo.NewHandle(state)
	defer h.Delete()
	if err := private.do(func(p *C.sogmm_options) C.sogmm_status {
		return C.sogmm_go_set_progress(p, C.uintptr_t(h))
	}); err != nil {
		return zero, err
	}
	r, err := create(private)
	return r, state.finish(err)
}

// finish raises a panic of the progress func again and gives a cancelled
// call's error its Cause.
func (s *progressState) finish(err error) error {
	if s.panicked {
		panic(s.panicVal)
	}
	if e, ok := err.(*Error); ok && e.Status == ErrCancelled {
		e.Cause = s.cause
	}
	return err
}

// withMapProgress runs f on m's handle with the progress callback of m set
// to report to m's progress func and watch ctx (sogmm_map_set_progress), and
// removed again afterwards; errors and panics as withProgress. The caller
// must have exclusive use of m, as for any insert.
func withMapProgress(ctx context.Context, m *Map, f func(p *C.sogmm_map) C.sogmm_status) error {
	state := &progressState{ctx: ctx, fn: m.progress}
	h := cgo.NewHandle(state)
	defer h.Delete()
	if err := m.do(func(p *C.sogmm_map) C.sogmm_status {
		return C.sogmm_go_map_set_progress(p, C.uintptr_t(h))
	}); err != nil {
		return err
	}
	// Removed (before the handle is deleted) on every path; cannot fail on an
	// open map that this call holds alone (Map.change).
	defer m.do(func(p *C.sogmm_map) C.sogmm_status { return C.sogmm_map_set_progress(p, nil, nil) })
	return state.finish(m.do(f))
}
