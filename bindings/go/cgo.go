// Package sogmm is the Go API of libsogmm: fit, store, load, sample and
// regress Self-Organizing Gaussian Mixture Models (4-D: x, y, z, gray) of
// RGB-D frames, over the library's C API.
//
// Linking: cgo links libsogmm dynamically (-lsogmm). The flags below look in
// this checkout's build/capi (where the top-level README builds it) and set
// an rpath to it, so a program using this package, also from another module
// through a `replace` line, runs with no environment variables. A build or
// install elsewhere is added with CGO_LDFLAGS, e.g.
//
//	CGO_LDFLAGS="-L$BUILD/capi -Wl,-rpath,$BUILD/capi" go test ./...
//
// which is what the ctest entries go_vet and go_test_race do. The header
// comes from this repository (capi/include), and the first handle created
// checks that the loaded library has the ABI version the header declares.
//
// Handles (*Model, *Options) own C memory: call Close when done. A finalizer
// frees a handle that was dropped without Close, as a safety net only (the
// Go GC does not see C memory, so it may run late). Close must not run
// concurrently with other calls on the same handle; all other methods of a
// Model may run concurrently (they only read it), except SetPose, ClearPose
// and SetValue, which need exclusive use, as in the C API's thread rules.
package sogmm

/*
#cgo CFLAGS: -I${SRCDIR}/../../capi/include
#cgo LDFLAGS: -L${SRCDIR}/../../build/capi -Wl,-rpath,${SRCDIR}/../../build/capi -lsogmm
#include <stdlib.h>
#include "sogmm/sogmm.h"
#if SOGMM_ABI_VERSION != 2
#error "these bindings are written for SOGMM_ABI_VERSION 2"
#endif
*/
import "C"
