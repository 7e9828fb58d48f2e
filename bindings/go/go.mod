// Go bindings of libsogmm (cgo over capi/include/sogmm/sogmm.h). No
// dependencies outside the standard library, hence no go.sum.
module sogmm

go 1.21
