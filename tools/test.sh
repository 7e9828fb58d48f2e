#!/usr/bin/env bash
# Runs every test of the project: installs dependencies and builds (via
# tools/setup.sh), runs the whole ctest suite (C++ core, format and
# conformance, C API, Python bindings, tools), then rebuilds the C API and core
# tests with AddressSanitizer + UndefinedBehaviorSanitizer and runs them.
#
# Usage: bash tools/test.sh          (README's test command; .ci/run calls it)
# Environment: SOGMM_SKIP_SANITIZE=1 skips the sanitizer pass (local use only).
set -euo pipefail
cd "$(dirname "$0")/.."
JOBS=$(nproc)

bash tools/setup.sh
echo "== tests (Release build) ==" >&2
ctest --test-dir build --output-on-failure --parallel "$JOBS" --timeout 900

if [ "${SOGMM_SKIP_SANITIZE:-0}" != 1 ]; then
  echo "== tests under AddressSanitizer + UndefinedBehaviorSanitizer ==" >&2
  cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSOGMM_SANITIZE=ON \
    -DSOGMM_BUILD_TOOLS=OFF >/dev/null
  cmake --build build-asan --parallel "$JOBS"
  ctest --test-dir build-asan --output-on-failure --parallel "$JOBS" --timeout 900 -R 'capi|format|conformance|core'
fi
