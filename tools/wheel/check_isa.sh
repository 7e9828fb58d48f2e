#!/usr/bin/env bash
# Fails when the libsogmm.so inside a wheel executes AVX/AVX2/AVX-512 or BMI
# instructions outside the code that chooses them at run time: the EM and
# query kernels of sogmm::detail::avx2 / ::avx512 (picked by em_dispatch.cpp
# after __builtin_cpu_supports; a template's name starts with its return
# type, hence the optional "void ") and the statically linked zstd (ZSTD_/HUF_/FSE_*,
# which tests the CPU itself). Anything else would crash with SIGILL on an
# older x86-64, e.g. a -march=native build or an inline function compiled
# with -mavx2 that the linker kept for every caller.
#
# Usage: bash tools/wheel/check_isa.sh WHEEL
set -euo pipefail
wheel=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
python3 -m zipfile -e "$wheel" "$tmp"
lib=$(ls "$tmp"/sogmm/_lib/libsogmm.so)
# VEX/EVEX-encoded instructions start with "v"; BMI1/2 and LZCNT by name.
bad=$(objdump -d --no-show-raw-insn -C "$lib" | awk '
  /^[0-9a-f]+ <.*>:$/ { fn = $0; next }
  /^ +[0-9a-f]+:\t(v[a-z0-9]+|andn|bextr|blsi|blsmsk|blsr|bzhi|shlx|shrx|sarx|rorx|mulx|pdep|pext|lzcnt|tzcnt)[ \t]/ {
    if (!(fn in seen)) { seen[fn] = 1; print fn } }' |
  grep -v -E '<(void )?sogmm::detail::(avx2|avx512)::|<(ZSTD|HUF|FSE|HIST)_' || true)
if [ -n "$bad" ]; then
  echo "check_isa: libsogmm.so uses AVX/BMI instructions outside the dispatched kernels:" >&2
  echo "$bad" | head -20 >&2
  exit 1
fi
echo "check_isa: only the dispatched kernels and zstd use AVX/BMI instructions"
