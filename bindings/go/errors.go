package sogmm

// #include "sogmm/sogmm.h"
import "C"

import (
	"errors"
	"fmt"
	"runtime"
	"sync"
)

// Status is a SOGMM_E_* code of the C API. It is itself an error, so the
// sentinels below work with errors.Is on any *Error.
type Status int32

// The C API's status codes (frozen; new ones are only appended).
const (
	ErrNullArg        Status = C.SOGMM_E_NULL_ARG
	ErrInvalidArg     Status = C.SOGMM_E_INVALID_ARG
	ErrInvalidData    Status = C.SOGMM_E_INVALID_DATA
	ErrNumeric        Status = C.SOGMM_E_NUMERIC
	ErrIO             Status = C.SOGMM_E_IO
	ErrFormat         Status = C.SOGMM_E_FORMAT
	ErrLimit          Status = C.SOGMM_E_LIMIT
	ErrNoMem          Status = C.SOGMM_E_NOMEM
	ErrBufferTooSmall Status = C.SOGMM_E_BUFFER_TOO_SMALL
	ErrNotFound       Status = C.SOGMM_E_NOT_FOUND
	ErrInternal       Status = C.SOGMM_E_INTERNAL
	ErrCancelled      Status = C.SOGMM_E_CANCELLED // a progress func or the context stopped the call
	ErrBusy           Status = C.SOGMM_E_BUSY      // map busy: another call is using the Map (see Map)
)

// ErrClosed is returned by methods of a handle after Close.
var ErrClosed = errors.New("sogmm: handle used after Close")

// Error implements error with the library's static description of the code.
func (s Status) Error() string {
	return fmt.Sprintf("sogmm: %s (%d)", C.GoString(C.sogmm_status_string(C.sogmm_status(s))), int32(s))
}

// Error is a failed call: its status and the message naming what was wrong.
// errors.Is(err, sogmm.ErrInvalidArg) and the like hold through Unwrap. A
// cancelled call (ErrCancelled) carries its Cause: the context's error or the
// error the progress func returned, so errors.Is(err, context.Canceled) holds
// too.
type Error struct {
	Status  Status
	Message string
	Cause   error
}

func (e *Error) Error() string {
	return fmt.Sprintf("sogmm: %s (%d): %s", C.GoString(C.sogmm_status_string(C.sogmm_status(e.Status))),
		int32(e.Status), e.Message)
}

// Unwrap returns the Status and the Cause (if any), for errors.Is and errors.As.
func (e *Error) Unwrap() []error {
	if e.Cause == nil {
		return []error{e.Status}
	}
	return []error{e.Status, e.Cause}
}

// call runs one C call and, on failure, reads the thread-local message on the
// same OS thread: the goroutine is locked to its thread for both (git2go's
// pattern), since the scheduler may otherwise move it between the two cgo
// calls and read another thread's message.
func call(f func() C.sogmm_status) error {
	runtime.LockOSThread()
	defer runtime.UnlockOSThread()
	st := f()
	if st == C.SOGMM_OK {
		return nil
	}
	return &Error{Status: Status(st), Message: C.GoString(C.sogmm_last_error())}
}

func invalidArg(format string, a ...any) error {
	return &Error{Status: ErrInvalidArg, Message: fmt.Sprintf(format, a...)}
}

var abiOnce = sync.OnceValue(func() error {
	if v := C.sogmm_abi_version(); v != C.SOGMM_ABI_VERSION {
		return &Error{Status: ErrInternal,
			Message: fmt.Sprintf("libsogmm has ABI version %d, these bindings need %d", v, C.SOGMM_ABI_VERSION)}
	}
	return nil
})

// Version is "MAJOR.MINOR.PATCH" of the loaded library.
func Version() string { return C.GoString(C.sogmm_version_string()) }
