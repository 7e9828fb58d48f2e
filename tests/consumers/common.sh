# Sourced by the consumer_* tests (arguments: <build-dir> <source-dir> ...).
# Gives a scratch folder outside the repository, removed on exit, and two
# clean environments, neither with LD_LIBRARY_PATH, CGO_LDFLAGS or SOGMM_LIB_DIR:
# - `clean` runs a command as from a fresh login shell: PATH and HOME only.
#   Programs are run (and checked) this way.
# - `tools` is `clean` plus the places where cargo, rustup and go keep their
#   toolchains and caches, when the caller's environment moved them away from
#   HOME, so that the builds reuse what the binding tests already compiled.
set -euo pipefail
BUILD=$(cd "$1" && pwd)
SRC=$(cd "$2" && pwd)
work=$(mktemp -d "${TMPDIR:-/tmp}/sogmm-consumer-XXXXXX")
trap 'rm -rf "$work"' EXIT
case "$work/" in
  "$SRC"/*) echo "scratch folder $work is inside the repository: set TMPDIR elsewhere" >&2; exit 1 ;;
esac

clean() { env -i PATH=/usr/bin:/bin HOME="${HOME:?}" "$@"; }
tools() {
  local v kept=()
  for v in CARGO_HOME RUSTUP_HOME GOCACHE GOMODCACHE GOPATH; do
    if [ -n "${!v:-}" ]; then kept+=("$v=${!v}"); fi
  done
  clean "${kept[@]}" "$@"
}

# check_runs <program> <libsogmm folder or 'static'>: runs the program on the
# scratch folder in a clean environment and checks which libsogmm it loaded
# (so a stray copy elsewhere on the system cannot make the test pass).
check_runs() {
  local program=$1 expected=$2 loaded
  # "libsogmm.so.2 => /path/libsogmm.so.2 (0x...)" or "... => not found".
  loaded=$(clean ldd "$program" | awk '$1 ~ /^libsogmm\.so/ {print $3, $4}')
  if [ "$expected" = static ]; then
    [ -z "$loaded" ] || { echo "FAIL: $program needs libsogmm.so ($loaded), expected libsogmm.a" >&2; exit 1; }
  else
    [ "${loaded%% *}" -ef "$expected/libsogmm.so.2" ] ||
      { echo "FAIL: $program: libsogmm.so.2 => '$loaded', expected $expected/libsogmm.so.2" >&2; exit 1; }
  fi
  # SOGMM_ISA (the EM/query kernel, not a way to find the library) is passed
  # on, so the result is checked under each kernel the suite runs with.
  clean ${SOGMM_ISA:+SOGMM_ISA="$SOGMM_ISA"} "$program" "$work"
}
