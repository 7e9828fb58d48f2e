#!/usr/bin/env bash
# ctest consumer_go: a Go module in a folder outside the repository, using the
# binding through a `replace` line, built and run with no environment
# variables (the go build cache under HOME is shared with go_test_race).
# The binding's cgo flags link <source>/build/capi with an rpath; a build folder
# elsewhere is passed the documented way, CGO_LDFLAGS (at build time only).
# Usage: consumer_go.sh <build> <source> <go>
. "$(dirname "$0")/common.sh"
go=$3
if [ ! -x "$go" ]; then
  echo "SKIP: go not found (install it to run consumer_go)"; exit 77
fi
cp -r "$SRC/tests/consumers/go" "$work/src"
cd "$work/src"
tools "$go" mod edit -replace "sogmm=$SRC/bindings/go"
flags=()
if [ ! "$BUILD/capi" -ef "$SRC/build/capi" ]; then
  flags=(CGO_LDFLAGS="-L$BUILD/capi -Wl,-rpath,$BUILD/capi")
fi
tools GOPROXY=off "${flags[@]}" "$go" build -o "$work/consumer" .
check_runs "$work/consumer" "$BUILD/capi"
