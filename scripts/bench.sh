#!/usr/bin/env bash
# `make bench`: the benchmark of issues 4 and 14. Builds relief-snake and make-scan (only those two
# targets) into $BUILD_DIR, installs matplotlib and numpy for the plots if missing, then runs
# bench/run_bench.py (bench/results/report.md and bench/results/*.png) and the randomized suite
# bench/random_suite.py (bench/results/random/report.md and results.json).
# It reports numbers; it does not fail on them (it exits non-zero only if it cannot run).
# Environment: BUILD_DIR [build], PYTHON [python3], JOBS [2] (build), BENCH_JOBS [2] (parallel
# runs), BENCH_ARGS (extra arguments for run_bench.py, e.g. --quick or --keep-scans),
# BENCH_SECTIONS ["main random extract whole detect"], RANDOM_SEEDS [0:200], RANDOM_ARGS (extra arguments for
# random_suite.py, e.g. --variant NAME=OPTIONS; without --variant it runs defaults, paper, auto-h, auto-side, old-defaults).
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

SECTIONS=${BENCH_SECTIONS:-main random extract whole detect}
# shellcheck disable=SC2086
if [[ " $SECTIONS " == *" main "* ]]; then
  "$PYTHON" bench/run_bench.py --build-dir "$BUILD_DIR" ${BENCH_ARGS:-}
fi
# shellcheck disable=SC2086
if [[ " $SECTIONS " == *" random "* ]]; then
  "$PYTHON" -m bench.random_suite --cli "$BUILD_DIR/relief-snake" --make-scan "$BUILD_DIR/make-scan" \
    --seeds "${RANDOM_SEEDS:-0:200}" --jobs "${BENCH_JOBS:-2}" --out bench/results/random ${RANDOM_ARGS:-}
fi
# shellcheck disable=SC2086
if [[ " $SECTIONS " == *" extract "* ]]; then
  mkdir -p bench/results
  "$PYTHON" bench/extract_bench.py --build "$BUILD_DIR" --triangles 100000,290000 --json bench/results/extract.json
fi
# Issue 13: holes and bands (bench/results/whole-reliefs), and detection on generated plates.
# shellcheck disable=SC2086
if [[ " $SECTIONS " == *" whole "* ]]; then
  "$PYTHON" -m bench.whole_reliefs --build "$BUILD_DIR" --out bench/results/whole-reliefs
fi
# shellcheck disable=SC2086
if [[ " $SECTIONS " == *" detect "* ]]; then
  "$PYTHON" bench/detect_suite.py --cli "$BUILD_DIR/relief-snake" --make-scan "$BUILD_DIR/make-scan" \
    --seeds 1:11 --backgrounds plane,cylinder,sphere --out bench/results/detect
fi
