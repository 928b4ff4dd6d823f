#!/usr/bin/env bash
# `make test-blender`: the add-on suite (tests/blender/run_tests.py) in Debian's Blender 3.4 and in
# bpy 4.5 LTS and bpy 5.2 LTS from PyPI, plus the bpy-free tests in plain Python. Needs the build
# (relief_snake_core for Python 3.11 in $BUILD_DIR, make-scan) and, for bpy 5.2, the cp313 module
# in $BUILD_DIR/py313 (scripts/package.sh builds it; this script builds it when it is missing).
# Fails if a Blender, a module or make-scan is missing: a suite that did not run is a failure.
set -euo pipefail
cd "$(dirname "$0")/.."

scripts/install-blender.sh >/dev/null
build_dir=${BUILD_DIR:-build}
case "$build_dir" in /*) ;; *) build_dir=$PWD/$build_dir ;; esac  # BUILD_DIR may be absolute
export RELIEF_SNAKE_BUILD_DIR=${RELIEF_SNAKE_BUILD_DIR:-$build_dir}
PYTHON=${PYTHON:-python3}

# Configured once, built every time (incremental): a module left from older sources would test them.
if [ ! -f "$build_dir/py313/CMakeCache.txt" ]; then
  echo "== configuring the cp313 module for bpy 5.2 (scripts/package.sh does the same)"
  PY313=${PY313:-$(ls /root/.pyenv/versions/3.13.*/bin/python3.13 "$HOME"/.pyenv/versions/3.13.*/bin/python3.13 2>/dev/null | head -1 || command -v python3.13)}
  VENV313=${VENV_PY313:-.venv-py313}
  "$VENV313/bin/python" -c "import pybind11" >/dev/null 2>&1 || { "$PY313" -m venv "$VENV313"; "$VENV313/bin/python" -m pip install -q pybind11; }
  cmake -S . -B "$build_dir/py313" -DCMAKE_BUILD_TYPE=Release -DRELIEF_SNAKE_BUILD_TESTS=OFF \
    -DPython3_EXECUTABLE="$PWD/$VENV313/bin/python" -Dpybind11_DIR="$("$VENV313/bin/python" -m pybind11 --cmakedir)" >/dev/null
fi
echo "== the cp313 module for bpy 5.2"
cmake --build "$build_dir/py313" --target relief_snake_core -j "${JOBS:-2}"

echo "== bpy-free add-on logic (pytest)"
"$PYTHON" -m pytest -q tests/blender

echo "== Debian Blender 3.4: blender --background"
blender --background --factory-startup --python-exit-code 1 --python tests/blender/run_tests.py

echo "== bpy 4.5 LTS from PyPI (Python 3.11)"
.venv-bpy45/bin/python tests/blender/run_tests.py

echo "== bpy 5.2 LTS from PyPI (Python 3.13, module from $build_dir/py313)"
RELIEF_SNAKE_MODULE_DIR="$build_dir/py313" .venv-bpy52/bin/python tests/blender/run_tests.py
echo "test-blender: Blender 3.4, bpy 4.5 and bpy 5.2 passed"
