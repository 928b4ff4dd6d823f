#!/usr/bin/env bash
# `make package`: the installable add-on zips in dist/ (or $DIST).
#   relief_snake-<version>-legacy.zip                Blender 3.x-4.1: Preferences > Add-ons > Install.
#       relief_snake/ = addon/relief_snake/*.py (bl_info) + the cp311 module + relief_snake_core.libs/
#   relief_snake-<version>-blender4.2-5.0-linux_x64.zip   Blender 4.2 .. 5.0 (Python 3.11): extension with
#       the cp311 wheel; manifest blender_version_min 4.2.0, blender_version_max 5.1.0.
#   relief_snake-<version>-blender5.1-5.3-linux_x64.zip   Blender 5.1 .. 5.3 (Python 3.13): extension with
#       the cp313 wheel; manifest blender_version_min 5.1.0, blender_version_max 5.4.0.
# One zip per Python, because a wheel only imports in the Python it was built for; the version
# ranges are what make Blender refuse the wrong zip instead of installing it and failing to import.
# Both are built and validated by Blender's own extension tool (blender_ext.py, the code behind
# `blender --command extension build|validate`, taken from the bpy 5.2 wheel in .venv-bpy52).
# Each zip holds one platform (linux-x64), so --split-platforms has nothing to split here.
#
# The cp311 module comes from the CMake build in $BUILD_DIR (the one `make build` and `make test`
# use); the cp313 module from a second configure of the module target only, in $BUILD_DIR/py313,
# with Python 3.13 ($PY313, default pyenv's) and pybind11 from PyPI (.venv-py313). Both are
# wrapped by scripts/build-wheel.sh --from-build (no second compile of the engine for cp311).
set -euo pipefail
cd "$(dirname "$0")/.."

PYTHON=${PYTHON:-python3}
BUILD_DIR=${BUILD_DIR:-build}
DIST=${DIST:-dist}
STAGE=${STAGE:-build-package}
ADDON=addon/relief_snake

version=$(sed -n 's/^version = "\(.*\)"$/\1/p' pyproject.toml | head -1)
manifest_version=$(sed -n 's/^version = "\(.*\)"$/\1/p' blender_manifest.toml | head -1)
cmake_version=$(sed -n 's/^project(relief_snake VERSION \([0-9.]*\).*/\1/p' CMakeLists.txt)
if [ "$version" != "$manifest_version" ] || [ "$version" != "$cmake_version" ]; then
  echo "package: versions differ (pyproject $version, blender_manifest $manifest_version, CMakeLists $cmake_version); make them equal" >&2
  exit 1
fi
if [ ! -f "$ADDON/__init__.py" ]; then
  echo "package: $ADDON/__init__.py is missing; the add-on must be there before packaging" >&2
  exit 1
fi

# --- the wheels ---------------------------------------------------------------
scripts/install-deps.sh
if [ ! -f "$BUILD_DIR/CMakeCache.txt" ]; then
  echo "package: configuring $BUILD_DIR (as make build does)" >&2
  cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release -DPython3_EXECUTABLE="$(command -v "$PYTHON")" >/dev/null
fi
cmake --build "$BUILD_DIR" --target relief_snake_core -j "${JOBS:-$(nproc)}"
mkdir -p "$DIST"
WHEEL_DIR="$DIST" PYTHON="$PYTHON" scripts/build-wheel.sh --from-build "$BUILD_DIR"

# cp313: Python 3.13 with pybind11 in .venv-py313, and the module target in $BUILD_DIR/py313.
PY313=${PY313:-$(ls /root/.pyenv/versions/3.13.*/bin/python3.13 "$HOME"/.pyenv/versions/3.13.*/bin/python3.13 2>/dev/null | head -1 || true)}
[ -n "$PY313" ] || PY313=$(command -v python3.13 || true)
if [ -z "$PY313" ]; then
  echo "package: Python 3.13 is needed for the cp313 wheel (Blender 5.1+); install it or set PY313" >&2
  exit 1
fi
VENV313=${VENV_PY313:-.venv-py313}
if ! "$VENV313/bin/python" -c "import pybind11" >/dev/null 2>&1; then
  echo "package: creating $VENV313 with $PY313 and pybind11" >&2
  "$PY313" -m venv "$VENV313"
  for i in 1 2 3; do "$VENV313/bin/python" -m pip install -q pybind11 && break; sleep 10; done
fi
B313="$BUILD_DIR/py313"
if [ ! -f "$B313/CMakeCache.txt" ]; then
  echo "package: configuring $B313 (module only, Python 3.13)" >&2
  cmake -S . -B "$B313" -DCMAKE_BUILD_TYPE=Release -DRELIEF_SNAKE_BUILD_TESTS=OFF \
    -DPython3_EXECUTABLE="$PWD/$VENV313/bin/python" -Dpybind11_DIR="$("$VENV313/bin/python" -m pybind11 --cmakedir)" >/dev/null
fi
cmake --build "$B313" --target relief_snake_core -j "${JOBS:-$(nproc)}"
WHEEL_DIR="$DIST" PYTHON="$VENV313/bin/python" scripts/build-wheel.sh --from-build "$B313"

wheel311=$(ls "$DIST"/relief_snake_core-"$version"-cp311-cp311-*.whl)
wheel313=$(ls "$DIST"/relief_snake_core-"$version"-cp313-cp313-*.whl)

rm -rf "$STAGE"
mkdir -p "$STAGE/legacy/relief_snake" "$STAGE/wheel"
"$PYTHON" -m zipfile -e "$wheel311" "$STAGE/wheel"

# Add-on sources: everything in addon/relief_snake/ except caches and compiled leftovers.
copy_addon() {
  (cd "$ADDON" && find . -type f ! -path '*/__pycache__/*' ! -name '*.pyc' ! -name '*.so' -print0) |
    while IFS= read -r -d '' f; do
      mkdir -p "$1/$(dirname "$f")"
      cp "$ADDON/$f" "$1/$f"
    done
}

# --- legacy add-on zip -------------------------------------------------------
legacy="$DIST/relief_snake-$version-legacy.zip"
copy_addon "$STAGE/legacy/relief_snake"
cp "$STAGE"/wheel/relief_snake_core.*.so "$STAGE/legacy/relief_snake/"
cp -r "$STAGE/wheel/relief_snake_core.libs" "$STAGE/legacy/relief_snake/"
rm -f "$legacy"
(cd "$STAGE/legacy" && zip -q -r -X "../legacy.zip" relief_snake)
mv "$STAGE/legacy.zip" "$legacy"
echo "package: $legacy"

# --- Blender 4.2+ extension zips, one per Python ------------------------------------------------
blender_ext=${BLENDER_EXT:-$(ls .venv-bpy52/lib/python3*/site-packages/bpy/*/scripts/addons_core/bl_pkg/cli/blender_ext.py 2>/dev/null | head -1 || true)}
if [ -z "$blender_ext" ]; then
  ONLY=bpy52 scripts/install-blender.sh
  blender_ext=$(ls .venv-bpy52/lib/python3*/site-packages/bpy/*/scripts/addons_core/bl_pkg/cli/blender_ext.py | head -1)
fi
rm -f "$DIST"/relief_snake-"$version"-linux_x64.zip  # the single zip of earlier versions

extension_zip() {  # extension_zip WHEEL MIN MAX LABEL
  local wheel=$1 min=$2 max=$3 label=$4 stage="$STAGE/extension-$4" out
  out="$DIST/relief_snake-$version-blender$label-linux_x64.zip"
  mkdir -p "$stage/wheels"
  copy_addon "$stage"
  cp "$wheel" "$stage/wheels/"
  # The manifest with this zip's wheel and Blender range (blender_manifest.toml is the template).
  "$PYTHON" - blender_manifest.toml "$stage/blender_manifest.toml" "./wheels/$(basename "$wheel")" "$min" "$max" <<'PY'
import re, sys
src, dst, wheel, lo, hi = sys.argv[1:6]
text = open(src).read()
text = re.sub(r'(?m)^blender_version_min = .*$', 'blender_version_min = "%s"' % lo, text)
text = re.sub(r'(?m)^blender_version_max = .*$', 'blender_version_max = "%s"' % hi, text)
text = re.sub(r'(?m)^wheels = \[.*\]$', 'wheels = ["%s"]' % wheel, text)
for key, want in (("blender_version_min", lo), ("blender_version_max", hi), ("wheels", wheel)):
    if want not in text:
        sys.exit("package: blender_manifest.toml has no %s line to fill" % key)
open(dst, "w").write(text)
PY
  rm -f "$out"
  # blender_ext.py needs only the standard library (3.11+ for tomllib).
  "$PYTHON" "$blender_ext" build --source-dir "$stage" --output-filepath "$out"
  "$PYTHON" "$blender_ext" validate "$out"
  echo "package: $out"
}
extension_zip "$wheel311" 4.2.0 5.1.0 4.2-5.0
extension_zip "$wheel313" 5.1.0 5.4.0 5.1-5.3
