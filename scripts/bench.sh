#!/usr/bin/env bash
# `make bench`: the benchmark of issue 4. Builds relief-snake and make-scan (only those two
# targets) into $BUILD_DIR, installs matplotlib and numpy for the plots if missing, then runs
# bench/run_bench.py, which writes bench/results/report.md and bench/results/*.png.
# It reports numbers; it does not fail on them (it exits non-zero only if it cannot run).
# Environment: BUILD_DIR [build], PYTHON [python3], JOBS [2] (build), BENCH_JOBS [2] (parallel
# accuracy runs), BENCH_ARGS (extra arguments for run_bench.py, e.g. --quick or --keep-scans).
set -euo pipefail
cd "$(dirname "$0")/.."

BUILD_DIR=${BUILD_DIR:-build}
PYTHON=${PYTHON:-python3}

if ! "$PYTHON" -c "import matplotlib, numpy" >/dev/null 2>&1; then
  echo "bench: pip install matplotlib numpy" >&2
  "$PYTHON" -m pip install -q matplotlib numpy ||
    "$PYTHON" -m pip install -q --break-system-packages matplotlib numpy
fi

echo "bench: building relief-snake and make-scan in $BUILD_DIR" >&2
cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release -DPython3_EXECUTABLE="$(command -v "$PYTHON")" >/dev/null
cmake --build "$BUILD_DIR" -j "${JOBS:-2}" --target relief-snake make-scan >/dev/null

# shellcheck disable=SC2086
exec "$PYTHON" bench/run_bench.py --build-dir "$BUILD_DIR" ${BENCH_ARGS:-}
