#!/usr/bin/env bash
# Regenerates the committed ABI baseline capi/abi/libsogmm.abi from a build's
# ABI image (builds only the target sogmm_abi_image). Run it only when the ABI
# changes on purpose: after adding a function (tools/abi/check_abi.sh then
# says so), or together with a SOGMM_ABI_VERSION bump for an incompatible
# change; commit the new baseline with the change (spec/api.md, "Evolution
# rules").
#
# Usage: bash tools/abi/update_baseline.sh [<build-dir>]   (default: build,
#        configured with the tests, without sanitizers)
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-$root/build}
cmake --build "$build" --target sogmm_abi_image
bash "$root/tools/abi/check_abi.sh" --write "$build/capi/abi-image/libsogmm.so"
git -C "$root" diff --stat -- capi/abi/libsogmm.abi 2>/dev/null || true
