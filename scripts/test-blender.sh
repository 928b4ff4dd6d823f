#!/usr/bin/env bash
# `make test-blender`: the add-on suite (tests/blender/run_tests.py) in both Blenders, plus the
# bpy-free tests in plain Python. Needs the build (relief_snake_core module, make-scan).
# Fails if either Blender, the module or make-scan is missing: a suite that did not run is a failure.
set -euo pipefail
cd "$(dirname "$0")/.."

scripts/install-blender.sh >/dev/null
build_dir=${BUILD_DIR:-build}
case "$build_dir" in /*) ;; *) build_dir=$PWD/$build_dir ;; esac  # BUILD_DIR may be absolute
export RELIEF_SNAKE_BUILD_DIR=${RELIEF_SNAKE_BUILD_DIR:-$build_dir}
unset RELIEF_SNAKE_FAKE_CORE  # the development-only fake engine never counts
PYTHON=${PYTHON:-python3}
VENV=${VENV_BPY:-.venv-bpy}

echo "== bpy-free add-on logic (pytest)"
"$PYTHON" -m pytest -q tests/blender/test_ordering.py

echo "== Debian Blender 3.4: blender --background"
blender --background --factory-startup --python-exit-code 1 --python tests/blender/run_tests.py

echo "== bpy 4.2 from PyPI: $VENV/bin/python"
"$VENV/bin/python" tests/blender/run_tests.py
echo "test-blender: both Blenders passed"
