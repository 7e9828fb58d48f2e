// A Go program outside the binding module (ctest consumer_go): the replace
// line points at a checkout's bindings/go; the package's cgo flags find
// libsogmm in that checkout's build/capi, with an rpath (bindings/go/README.md).
module sogmm-consumer

go 1.21

require sogmm v0.0.0

replace sogmm => ../../../bindings/go
