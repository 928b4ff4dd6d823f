#!/usr/bin/env bash
# Makes the scans examples/batch/manifest.json names (make-scan, after `make build`), then:
#   build/relief-snake batch examples/batch/manifest.json --out /tmp/batch-example
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
make_scan=${MAKE_SCAN:-$here/../../build/make-scan}
mkdir -p "$here/scans"
"$make_scan" --shape duck --triangles 60000 --out "$here/scans/duck" >/dev/null
"$make_scan" --shape disk --triangles 20000 --step blended --out "$here/scans/disk" >/dev/null
"$make_scan" --shape rectangle --triangles 20000 --background cylinder --out "$here/scans/panel" >/dev/null
"$make_scan" --shape disk --triangles 20000 --seed 7 --out "$here/scans/plate" >/dev/null
echo "wrote $here/scans/{duck,disk,panel,plate}.ply and their truth files"
