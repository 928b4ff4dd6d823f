#!/usr/bin/env bash
# make fuzz: builds the libFuzzer targets (clang, ASan+UBSan) in $FUZZ_DIR and runs each for
# $FUZZ_SECONDS on a working corpus seeded from fuzz/corpus and fuzz/regression. Limits: 2 GB
# RSS and 2 GB per allocation, 60 s per input (a single segment() on a small mesh takes ~0.05 s
# natively, but ASan+UBSan on a loaded 2-core machine has been seen at 12 s). Exits non-zero on any finding, whose input is
# written to $FUZZ_DIR/findings/<target>/ (add it to fuzz/regression/<target>/).
# FUZZ_TARGETS (default "mesh_intake segment") picks the libFuzzer targets, FUZZ_ATHERIS=0 skips the
# module harness. Every run appends one line per target to $FUZZ_DIR/campaign.log (date, target,
# seconds, executions, corpus size): `make fuzz-campaign` sums them.
set -euo pipefail
cd "$(dirname "$0")/.."
FUZZ_SECONDS=${FUZZ_SECONDS:-60}
FUZZ_DIR=${FUZZ_DIR:-build-fuzz}
JOBS=${JOBS:-2}
PYTHON=${PYTHON:-python3}
FUZZ_TARGETS=${FUZZ_TARGETS:-mesh_intake segment}
FUZZ_ATHERIS=${FUZZ_ATHERIS:-1}

cmake -S . -B "$FUZZ_DIR" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ \
  -DRELIEF_SNAKE_FUZZ=ON -DRELIEF_SNAKE_BUILD_TESTS=OFF -DRELIEF_SNAKE_BUILD_PYTHON=OFF >/dev/null
cmake --build "$FUZZ_DIR" -j "$JOBS" --target fuzz_mesh_intake fuzz_segment

status=0
for target in $FUZZ_TARGETS; do
  corpus_name=$([ "$target" = mesh_intake ] && echo intake || echo segment)
  work="$FUZZ_DIR/corpus/$corpus_name"
  findings="$FUZZ_DIR/findings/$corpus_name"
  mkdir -p "$work" "$findings"
  log="$FUZZ_DIR/fuzz_$target.log"
  echo "fuzz: $target for ${FUZZ_SECONDS} s (log: $log)"
  if ! UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 ASAN_OPTIONS=detect_leaks=1 \
      "$FUZZ_DIR/fuzz_$target" -max_total_time="$FUZZ_SECONDS" -rss_limit_mb=2048 -malloc_limit_mb=2048 \
      -timeout=60 -report_slow_units=30 -print_final_stats=1 -artifact_prefix="$findings/" \
      "$work" "fuzz/corpus/$corpus_name" "fuzz/regression/$corpus_name" >"$log" 2>&1; then
    status=1
    echo "fuzz: $target FOUND A PROBLEM; input(s) in $findings/, log $log:" >&2
    grep -E "ERROR|SUMMARY|runtime error|Test unit written" "$log" | head -20 >&2 || true
  fi
  execs=$(grep -o "stat::number_of_executed_units: *[0-9]*" "$log" | grep -o "[0-9]*$" || echo "?")
  echo "fuzz: $target: $execs executions, corpus $(ls "$work" | wc -l) inputs"
  echo "$(date -u +%Y-%m-%dT%H:%M:%SZ) $target $FUZZ_SECONDS $execs $(ls "$work" | wc -l)" >>"$FUZZ_DIR/campaign.log"
done
if [ "$FUZZ_ATHERIS" = 0 ]; then exit $status; fi
# The module's argument handling (atheris; the module from $BUILD_DIR, not instrumented).
BUILD_DIR=${BUILD_DIR:-build}
log="$FUZZ_DIR/atheris_module.log"
mkdir -p "$FUZZ_DIR/findings/module" "$FUZZ_DIR/corpus/module"
echo "fuzz: module arguments (atheris) for ${FUZZ_SECONDS} s (log: $log)"
if ! RELIEF_SNAKE_BUILD_DIR="$BUILD_DIR" "$PYTHON" fuzz/atheris_module.py -max_total_time="$FUZZ_SECONDS" \
    -rss_limit_mb=2048 -timeout=10 -print_final_stats=1 -artifact_prefix="$FUZZ_DIR/findings/module/" \
    "$FUZZ_DIR/corpus/module" >"$log" 2>&1; then
  status=1
  echo "fuzz: module arguments FOUND A PROBLEM; see $log" >&2
  tail -20 "$log" >&2
fi
execs=$(grep -o "stat::number_of_executed_units: *[0-9]*" "$log" | grep -o "[0-9]*$" || echo "?")
echo "fuzz: module arguments: $execs executions"
exit $status
