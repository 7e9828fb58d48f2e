#!/usr/bin/env bash
# Compares the ABI of a built libsogmm with the committed baseline
# capi/abi/libsogmm.abi, using libabigail (Debian package abigail-tools).
# Builds nothing: give it the ABI image of a build, <build>/capi/abi-image/
# libsogmm.so (the shipped Release library carries no DWARF, so no types).
#
# Usage: check_abi.sh <libsogmm.so with DWARF> [<baseline.abi>]
#        check_abi.sh --write <libsogmm.so with DWARF> [<baseline.abi>]
#          (regenerates the baseline; tools/abi/update_baseline.sh wraps it)
#
# The ABI is the exported functions and the public types reachable from them:
# abidw reads it with capi/include as the only public headers, so the
# library's private structs stay opaque, and without source locations, so
# the baseline changes only when the interface does.
#
# abidiff's exit status is a bit field (abidiff(1), "RETURN VALUES"): 1 tool
# error, 2 usage error, 4 the ABIs differ, 8 incompatible change (today only
# a removed function or variable). A changed signature or type sets 4 alone,
# as does an added function, so a 4 without 8 is run again with
# --no-added-syms: if the difference stays, something changed.
# Exit: 0 = same ABI, or additions only (with a note to refresh the
# baseline); 1 = removed function, changed signature or type, or an error.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)

write=0
if [ "${1:-}" = --write ]; then write=1; shift; fi
if [ $# -lt 1 ] || [ $# -gt 2 ]; then
  echo "usage: $0 [--write] <libsogmm.so with debug info> [<baseline.abi>]" >&2; exit 1
fi
lib=$1
baseline=${2:-$root/capi/abi/libsogmm.abi}

for tool in abidw abidiff; do
  command -v "$tool" >/dev/null || { echo "FAIL: $tool not found (install abigail-tools: tools/setup.sh)"; exit 1; }
done
[ -f "$lib" ] || { echo "FAIL: no library at $lib"; exit 1; }
# Without DWARF abidw sees only symbol names: the check would miss every
# signature change, so refuse instead of passing.
if ! readelf -S -W "$lib" | grep -q '\.debug_info'; then
  echo "FAIL: $lib has no debug info; give the ABI image (<build>/capi/abi-image/libsogmm.so)"; exit 1
fi

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
abidw --headers-dir "$root/capi/include" --drop-private-types --exported-interfaces-only \
  --no-corpus-path --no-comp-dir-path --no-show-locs --no-elf-needed --type-id-style hash \
  --out-file "$tmp/current.abi" "$lib"
functions=$(grep -c '<function-decl .*elf-symbol-id=' "$tmp/current.abi" || true)
if [ "$functions" -eq 0 ]; then echo "FAIL: abidw found no exported function in $lib"; exit 1; fi

if [ $write = 1 ]; then
  # Source paths relative to the checkout, so the baseline does not depend on it.
  sed "s|path='[^']*/capi/src/|path='capi/src/|" "$tmp/current.abi" > "$baseline"
  echo "wrote $baseline: $functions exported functions"
  exit 0
fi

[ -f "$baseline" ] || { echo "FAIL: no baseline at $baseline"; exit 1; }
rc=0
abidiff "$baseline" "$tmp/current.abi" > "$tmp/report" 2>&1 || rc=$?
if [ $rc -eq 0 ]; then
  echo "OK: ABI of $lib equals the baseline ($functions exported functions)"; exit 0
fi
cat "$tmp/report"
if [ $((rc & 3)) -ne 0 ]; then echo "FAIL: abidiff error (exit $rc)"; exit 1; fi
if [ $((rc & 8)) -ne 0 ]; then
  echo "FAIL: incompatible ABI change: a function or variable was removed (abidiff exit $rc)"; exit 1
fi
rc2=0
abidiff --no-added-syms "$baseline" "$tmp/current.abi" > /dev/null 2>&1 || rc2=$?
if [ $rc2 -ne 0 ]; then
  echo "FAIL: ABI change: a function signature or a public type changed (abidiff exit $rc)"; exit 1
fi
echo "OK: only additions to the baseline's ABI. Refresh the baseline in the same change:"
echo "    bash tools/abi/update_baseline.sh    (spec/api.md, \"Evolution rules\")"
