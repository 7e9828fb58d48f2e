#!/usr/bin/env bash
# Runs the libFuzzer targets of tests/fuzz, either for a bounded time each
# (a random search: the long campaign) or for a fixed number of runs from a
# fixed seed (deterministic: what tools/test.sh and CI run).
#
# Usage: bash tests/fuzz/run_long.sh [--seconds S | --runs N [--seed X]] [--jobs J] [--build DIR]
#                                    [--no-build] [TARGET[=RUNS]...]
#   --seconds S  time per target (default 3600), random seed, corpus kept and
#                grown in DIR/fuzz-corpus/<target> across runs
#   --runs N     exactly N inputs per target from seed X (default 1), starting
#                from the committed seeds and regressions only (a fresh corpus
#                each time), no time limit: the same commit gives the same
#                inputs and so the same verdict on every run
#   --keep-going with --seconds: a crash does not end the target (libFuzzer
#                -fork=1 -ignore_crashes ...): every finding of the campaign is
#                kept in DIR/fuzz-artifacts/<target>/, and the script fails if
#                there is any
#   --fork F     with --keep-going: F libFuzzer worker processes per target
#                (default 1), so that one target can use several cores
#   --jobs J     targets run at the same time (default 1)
#   --build DIR  fuzz build folder (default build-fuzz), configured here with
#                clang, -DSOGMM_SANITIZE=ON -DSOGMM_FUZZ=ON unless --no-build
#   TARGET       load_memory load_file verify fit api map (default: all); with
#                --runs, TARGET=RUNS gives that target its own run count
#                (the targets' speeds differ by 100x)
# Corpus: each format target starts from the spec/conformance .sogmm vectors,
# fit, api and map from tests/fuzz/seeds/<target>; all from tests/fuzz/regressions/<target>; what it
# finds is kept in DIR/fuzz-corpus/<target>. A crash writes its input to
# DIR/fuzz-artifacts/<target>/ and makes this script fail: turn it into a
# regression (tests/fuzz/regressions/<target>/, see README.md there).
# Prints, per target, the executions run and the outcome.
set -euo pipefail
cd "$(dirname "$0")/../.."

SECONDS_PER_TARGET=3600
RUNS=""
FUZZ_SEED=1
KEEP_GOING=0
FORK=1
JOBS=1
BUILD=build-fuzz
DO_BUILD=1
TARGETS=()
while [ $# -gt 0 ]; do
  case "$1" in
    --seconds) SECONDS_PER_TARGET=$2; shift 2 ;;
    --runs) RUNS=$2; shift 2 ;;
    --seed) FUZZ_SEED=$2; shift 2 ;;
    --keep-going) KEEP_GOING=1; shift ;;
    --fork) FORK=$2; shift 2 ;;
    --jobs) JOBS=$2; shift 2 ;;
    --build) BUILD=$2; shift 2 ;;
    --no-build) DO_BUILD=0; shift ;;
    -h|--help) sed -n '2,34p' "$0"; exit 0 ;;
    *) TARGETS+=("$1"); shift ;;
  esac
done
[ ${#TARGETS[@]} -gt 0 ] || TARGETS=(load_memory load_file verify fit api map)
# TARGET=RUNS: split into the target names and their run counts.
declare -A RUNS_OF=()
for i in "${!TARGETS[@]}"; do
  case "${TARGETS[$i]}" in
    *=*) RUNS_OF[${TARGETS[$i]%%=*}]=${TARGETS[$i]#*=}; TARGETS[$i]=${TARGETS[$i]%%=*} ;;
  esac
done

if [ "$DO_BUILD" = 1 ]; then
  # -O1 with line tables, libFuzzer's advice (and tools/test.sh's other
  # sanitizer builds): the instrumented core compiles about 2x faster than at -O2 -g.
  CC=clang CXX=clang++ cmake -S . -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" \
    -DSOGMM_SANITIZE=ON -DSOGMM_FUZZ=ON -DSOGMM_BUILD_TOOLS=OFF >/dev/null
  cmake --build "$BUILD" --parallel "$(nproc)" --target "${TARGETS[@]/#/sogmm_fuzz_}"
fi

# Per-input limits: a slow input (> 25 s) or more than 2 GiB of memory is a finding too.
max_len_for() { case "$1" in fit) echo 4200 ;; map) echo 8192 ;; *) echo 40000 ;; esac; }

# Seeds of the format targets: the .sogmm conformance vectors (not the .json dumps).
SEEDS="$BUILD/fuzz-seeds/sogmm"
rm -rf "$SEEDS" && mkdir -p "$SEEDS"
cp spec/conformance/valid/*.sogmm spec/conformance/invalid/*.sogmm "$SEEDS/"

# What bounds a run: wall time and a random seed, or a run count and a fixed
# seed (then the corpus starts empty so that earlier runs cannot change it).
budget_flags() {
  if [ -n "$RUNS" ]; then echo "-runs=${RUNS_OF[$1]:-$RUNS} -seed=$FUZZ_SEED -reload=0"; return; fi
  echo "-max_total_time=$SECONDS_PER_TARGET"
  if [ "$KEEP_GOING" = 1 ]; then echo "-fork=$FORK -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1"; fi
}
budget_words() {
  if [ -n "$RUNS" ]; then echo "from seed $FUZZ_SEED"; else echo "in ${SECONDS_PER_TARGET} s"; fi
}

run_one() {
  local t=$1
  local corpus="$BUILD/fuzz-corpus/$t" artifacts="$BUILD/fuzz-artifacts/$t" log="$BUILD/fuzz-logs/$t.log"
  if [ -n "$RUNS" ]; then corpus="$BUILD/fuzz-corpus-seeded/$t"; rm -rf "$corpus" "$artifacts"; fi
  mkdir -p "$corpus" "$artifacts" "$(dirname "$log")"
  local dirs=("$corpus") d
  case "$t" in fit|api|map) ;; *) dirs+=("$SEEDS") ;; esac
  for d in "tests/fuzz/seeds/$t" "tests/fuzz/regressions/$t"; do
    if [ -d "$d" ]; then dirs+=("$d"); fi
  done
  local status=0 cpu
  # A seeded run must execute the same code on every machine and every run:
  # a fixed environment (libFuzzer's coverage shifted with the caller's
  # variables), no address randomisation (it shifted with the addresses) and
  # the same EM/query kernels on every CPU: SOGMM_ISA=sse2, because the AVX2
  # and AVX-512 kernels round differently, so a wider CPU fits other models,
  # covers other code and once reached a finding the 2-core CI machine's
  # AVX2 run never saw (the same commit must get the same verdict anywhere).
  local launch=(env)
  if [ -n "$RUNS" ]; then
    launch=(env -i PATH=/usr/bin:/bin LANG=C.UTF-8 TMPDIR=/tmp SOGMM_ISA=sse2 setarch "$(uname -m)" -R env)
  fi
  local TIMEFORMAT="%U %S"  # CPU seconds (user, system) of the target and its forks
  { time "${launch[@]}" \
  OMP_NUM_THREADS=1 \
  ASAN_OPTIONS="detect_leaks=1:abort_on_error=1" \
  UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1" \
    "$BUILD/tests/fuzz/sogmm_fuzz_$t" "${dirs[@]}" \
      $(budget_flags "$t") -timeout=25 -rss_limit_mb=2048 -max_len="$(max_len_for "$t")" \
      -artifact_prefix="$artifacts/" -print_final_stats=1 >"$log" 2>&1; } 2>"$log.cpu" || status=$?
  local execs findings
  # '|| true': under pipefail a grep that finds nothing would end this
  # function before it reports (fork mode never prints the final stats).
  execs=$(grep -ao 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' | tail -1 || true)
  # Fork mode prints running totals as '#N: cov: ...' instead.
  [ -n "$execs" ] || execs=$(grep -aoE '^#[0-9]+:' "$log" | tr -d '#:' | tail -1 || true)
  findings=$(find "$artifacts" -type f | wc -l)
  cpu=$(awk '{printf "%.0f", $1 + $2}' "$log.cpu" 2>/dev/null || echo "?")
  if [ "$KEEP_GOING" = 1 ] && [ "$findings" -gt 0 ]; then status=1; fi
  if [ "$status" = 0 ]; then
    echo "fuzz $t: ${execs:-?} executions $(budget_words) (${cpu} CPU s), no crash"
  elif [ "$KEEP_GOING" = 1 ]; then
    echo "fuzz $t: ${execs:-?} executions $(budget_words) (${cpu} CPU s), $findings findings in $artifacts"
  else
    echo "fuzz $t: FAILED (exit $status) after ${execs:-?} executions; log $log; inputs:" \
      "$(ls "$artifacts" 2>/dev/null | tr '\n' ' ')"
    grep -m 20 -E 'ERROR|SUMMARY|runtime error|invariant violated|last sogmm error|==[0-9]+==' "$log" || true
  fi
  return "$status"
}

failed=0
pids=()
names=()
for t in "${TARGETS[@]}"; do
  run_one "$t" &
  pids+=($!)
  names+=("$t")
  while [ "$(jobs -rp | wc -l)" -ge "$JOBS" ]; do sleep 1; done
done
for i in "${!pids[@]}"; do
  wait "${pids[$i]}" || failed=1
done
exit $failed
