#!/usr/bin/env bash
# `make demo`: the bundled sample scan (a synthetic duck relief from make-scan), segmented
# headless in Debian's Blender by examples/segment_scan.py; prints where the .blend and PNG went.
# The picture: an oblique view of the scan with the picks (blue), the outline (orange) and the
# relief (tan), and beside it a sphere with the extracted relief applied to it, titled. The
# extraction's height map goes to $OUT/extract/.
# `make demo` builds first; run directly, this script builds too if the build is missing.
set -euo pipefail
cd "$(dirname "$0")/.."

BUILD_DIR=${BUILD_DIR:-build}
OUT=${DEMO_OUT:-demo-output}
TRIANGLES=${DEMO_TRIANGLES:-60000}
PYTHON=${PYTHON:-python3}

if ! ls "$BUILD_DIR"/relief_snake_core*.so >/dev/null 2>&1 || [ ! -x "$BUILD_DIR/make-scan" ]; then
  echo "demo: building into $BUILD_DIR" >&2
  cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release -DPython3_EXECUTABLE="$(command -v "$PYTHON")" >/dev/null
  cmake --build "$BUILD_DIR" -j "${JOBS:-2}" --target relief_snake_core make-scan
fi
command -v blender >/dev/null 2>&1 || scripts/install-blender.sh

mkdir -p "$OUT"
echo "demo: writing the sample scan ($TRIANGLES triangles) to $OUT/duck.ply"
"$BUILD_DIR/make-scan" --shape duck --background plane --triangles "$TRIANGLES" --step blended --seed 1 \
  --out "$OUT/duck" >/dev/null

echo "demo: segmenting in $(blender --version 2>/dev/null | head -1) (headless)"
rm -rf "$OUT/duck.blend" "$OUT/duck.png" "$OUT/extract"
status=0
blender --background --factory-startup --python-exit-code 1 --python examples/segment_scan.py -- \
  --mesh "$OUT/duck.ply" --truth "$OUT/duck.truth.json" --out "$OUT" --build-dir "$BUILD_DIR" \
  --extract "$OUT/extract" \
  >"$OUT/blender.log" 2>&1 || status=$?
grep -E '^(segment_scan|Relief Snake|  [a-z]+: )' "$OUT/blender.log" || true
if [ "$status" -ne 0 ] || [ ! -s "$OUT/duck.blend" ] || [ ! -s "$OUT/duck.png" ] || [ ! -s "$OUT/extract/duck_Height.exr" ]; then
  echo "demo: the Blender run failed (exit $status); see $OUT/blender.log" >&2
  tail -20 "$OUT/blender.log" >&2
  exit 1
fi
echo "demo: .blend   $(cd "$OUT" && pwd)/duck.blend"
echo "demo: picture  $(cd "$OUT" && pwd)/duck.png (the scan, and the relief applied to a sphere)"
echo "demo: height   $(cd "$OUT" && pwd)/extract/duck_Height.exr"
