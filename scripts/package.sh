#!/usr/bin/env bash
# `make package`: the two installable add-on zips in dist/.
#   dist/relief_snake-<version>-legacy.zip     Blender 3.x-4.1: Preferences > Add-ons > Install.
#       relief_snake/ = addon/relief_snake/*.py (bl_info) + the compiled module + relief_snake_core.libs/
#   dist/relief_snake-<version>-linux_x64.zip  Blender 4.2+ extension: blender_manifest.toml,
#       the add-on's files and wheels/relief_snake_core-*.whl, built and validated by Blender's
#       own extension tool (blender_ext.py from the bpy 4.2 wheel in .venv-bpy).
# The compiled module comes from the CMake build in $BUILD_DIR (default build/), the one
# `make build` and `make test` use: configured like `make build` when it does not exist yet,
# then only the relief_snake_core target is brought up to date, and scripts/build-wheel.sh
# --from-build wraps it into the wheel (no second compile of the engine; `make test` packages
# and tests what it just built). WHEEL_FROM=scikit-build builds the wheel with scikit-build-core
# in build-wheel/ instead (as `make wheel` does).
# The add-on imports the module as `from . import relief_snake_core` (legacy zip) and falls
# back to `import relief_snake_core` (the extension's wheel).
set -euo pipefail
cd "$(dirname "$0")/.."

PYTHON=${PYTHON:-python3}
BUILD_DIR=${BUILD_DIR:-build}
WHEEL_FROM=${WHEEL_FROM:-build}
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

# --- the wheel -------------------------------------------------------------
case "$WHEEL_FROM" in
  build)
    scripts/install-deps.sh
    if [ ! -f "$BUILD_DIR/CMakeCache.txt" ]; then
      echo "package: configuring $BUILD_DIR (as make build does)" >&2
      cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release -DPython3_EXECUTABLE="$(command -v "$PYTHON")" >/dev/null
    fi
    cmake --build "$BUILD_DIR" --target relief_snake_core -j "${JOBS:-$(nproc)}"
    WHEEL_DIR="$DIST" PYTHON="$PYTHON" scripts/build-wheel.sh --from-build "$BUILD_DIR"
    ;;
  scikit-build)
    WHEEL_DIR="$DIST" PYTHON="$PYTHON" scripts/build-wheel.sh
    ;;
  *)
    echo "package: WHEEL_FROM must be build or scikit-build, not '$WHEEL_FROM'" >&2
    exit 1
    ;;
esac
wheel=$(ls "$DIST"/relief_snake_core-"$version"-*.whl)
wheel_name=$(basename "$wheel")
if ! grep -q "\"./wheels/$wheel_name\"" blender_manifest.toml; then
  echo "package: blender_manifest.toml must list \"./wheels/$wheel_name\" in wheels; update it" >&2
  exit 1
fi

rm -rf "$STAGE"
mkdir -p "$STAGE/legacy/relief_snake" "$STAGE/extension/wheels" "$STAGE/wheel"
"$PYTHON" -m zipfile -e "$wheel" "$STAGE/wheel"

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

# --- Blender 4.2+ extension zip ------------------------------------------------
blender_ext=${BLENDER_EXT:-$(ls .venv-bpy/lib/python3*/site-packages/bpy/*/scripts/addons_core/bl_pkg/cli/blender_ext.py 2>/dev/null | head -1 || true)}
if [ -z "$blender_ext" ]; then
  scripts/install-blender.sh
  blender_ext=$(ls .venv-bpy/lib/python3*/site-packages/bpy/*/scripts/addons_core/bl_pkg/cli/blender_ext.py | head -1)
fi
extension="$DIST/relief_snake-$version-linux_x64.zip"
copy_addon "$STAGE/extension"
cp blender_manifest.toml "$STAGE/extension/"
cp "$wheel" "$STAGE/extension/wheels/"
rm -f "$extension"
# blender_ext.py needs only the standard library (3.11+ for tomllib).
"$PYTHON" "$blender_ext" build --source-dir "$STAGE/extension" --output-filepath "$extension"
"$PYTHON" "$blender_ext" validate "$extension"
echo "package: $extension"
