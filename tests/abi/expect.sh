#!/usr/bin/env bash
# Runs a check and asserts its outcome, so that the ABI checks are shown to
# fail for the right reason (not for a missing tool or a broken shim).
# Usage: expect.sh <pass|fail> <ERE>... -- <command> [args...]
# Passes when the command exits 0 (pass) or non-zero (fail) and every
# extended regular expression matches a line of its output.
set -uo pipefail
want=$1; shift
patterns=()
while [ $# -gt 0 ] && [ "$1" != -- ]; do patterns+=("$1"); shift; done
[ $# -gt 1 ] || { echo "usage: expect.sh <pass|fail> <ERE>... -- <command...>"; exit 2; }
shift
out=$("$@" 2>&1); rc=$?
printf '%s\n' "$out"
if [ "$want" = pass ] && [ $rc -ne 0 ]; then echo "EXPECTED success, got exit $rc"; exit 1; fi
if [ "$want" = fail ] && [ $rc -eq 0 ]; then echo "EXPECTED failure, got exit 0"; exit 1; fi
for p in "${patterns[@]}"; do
  printf '%s\n' "$out" | grep -Eq -- "$p" || { echo "EXPECTED output matching: $p"; exit 1; }
done
echo "as expected: $want (exit $rc)"
