#!/usr/bin/env bash
# Builds the relief_snake_core wheel into dist/ (or $WHEEL_DIR):
#   dist/relief_snake_core-<version>-cp311-cp311-linux_x86_64.whl
# scikit-build-core builds only the module target (no tests); Debian's libOpenMeshCore
# is bundled in relief_snake_core.libs/ with RPATH $ORIGIN (see CMakeLists.txt).
# Idempotent: installs the build tools only when missing; reuses build-wheel/ between runs.
set -euo pipefail
cd "$(dirname "$0")/.."

PYTHON=${PYTHON:-python3}
WHEEL_DIR=${WHEEL_DIR:-dist}
export CMAKE_BUILD_PARALLEL_LEVEL=${CMAKE_BUILD_PARALLEL_LEVEL:-2}  # the machine has 2 shared cores

scripts/install-deps.sh
if ! "$PYTHON" -c "import scikit_build_core, pybind11" >/dev/null 2>&1; then
  echo "build-wheel: pip install scikit-build-core pybind11" >&2
  "$PYTHON" -m pip install -q "scikit-build-core>=0.10" "pybind11>=2.10"
fi

mkdir -p "$WHEEL_DIR"
rm -f "$WHEEL_DIR"/relief_snake_core-*.whl
# No build isolation: use the tools installed above (no index access needed at build time)
# and keep the CMake build directory for incremental rebuilds.
"$PYTHON" -m pip wheel . --no-deps --no-build-isolation -q -w "$WHEEL_DIR" \
  --config-settings=build-dir=build-wheel

wheel=$(ls "$WHEEL_DIR"/relief_snake_core-*.whl)
# The wheel must carry libOpenMeshCore and find it through $ORIGIN, not through the system.
"$PYTHON" - "$wheel" <<'PY'
import sys, zipfile
names = zipfile.ZipFile(sys.argv[1]).namelist()
mods = [n for n in names if n.startswith("relief_snake_core.") and n.endswith(".so")]
libs = [n for n in names if n.startswith("relief_snake_core.libs/libOpenMeshCore.so")]
if not mods or not libs:
    sys.exit(f"build-wheel: {sys.argv[1]} lacks the module or the bundled libOpenMeshCore: {names}")
PY
echo "build-wheel: $wheel"
