#!/usr/bin/env bash
# Builds the relief_snake_core wheel for $PYTHON into dist/ (or $WHEEL_DIR):
#   dist/relief_snake_core-<version>-cp311-cp311-manylinux_2_<N>_x86_64.whl   (PYTHON=python3.11)
#   dist/relief_snake_core-<version>-cp313-cp313-manylinux_2_<N>_x86_64.whl   (PYTHON=python3.13)
# The platform tag tells the truth: `auditwheel show` (from PyPI, in .venv-wheeltools) reads the
# glibc / libstdc++ symbol versions the module and its bundled library need and names the
# manylinux policy they fit; the wheel is tagged with it (the build fails if none fits).
# Two ways, one content (the module and Debian's libOpenMeshCore in relief_snake_core.libs/,
# found through RUNPATH $ORIGIN/relief_snake_core.libs, not through the system):
#
#   scripts/build-wheel.sh                    (`make wheel`) scikit-build-core builds the module
#       target from scratch in build-wheel/ (the SKBUILD block in CMakeLists.txt sets the RPATH
#       and installs the library). Idempotent; reuses build-wheel/ between runs.
#   scripts/build-wheel.sh --from-build DIR   (`make package`, `make test`) wraps the module
#       that the CMake build in DIR already compiled (same CMakeLists.txt, Release; pybind11
#       strips it) instead of compiling the engine a second time: copies it and the
#       libOpenMeshCore it links, sets the RUNPATH with patchelf and writes the .dist-info
#       (METADATA from pyproject.toml, WHEEL with the running Python's tag, RECORD).
#       DIR must be a Release build for the same Python as $PYTHON (the module's suffix).
set -euo pipefail
cd "$(dirname "$0")/.."

PYTHON=${PYTHON:-python3}
WHEEL_DIR=${WHEEL_DIR:-dist}
export CMAKE_BUILD_PARALLEL_LEVEL=${CMAKE_BUILD_PARALLEL_LEVEL:-2}  # the machine has 2 shared cores

from_build=""
if [ "${1:-}" = "--from-build" ]; then
  from_build=${2:?"build-wheel: --from-build needs the CMake build directory"}
elif [ $# -gt 0 ]; then
  echo "build-wheel: unknown argument $1 (use no argument, or --from-build DIR)" >&2
  exit 2
fi

scripts/install-deps.sh
mkdir -p "$WHEEL_DIR"
py_tag=$("$PYTHON" -c 'import sys; print("cp%d%d" % sys.version_info[:2])')
rm -f "$WHEEL_DIR"/relief_snake_core-*-"$py_tag"-*.whl

if [ -z "$from_build" ]; then
  if ! "$PYTHON" -c "import scikit_build_core, pybind11" >/dev/null 2>&1; then
    echo "build-wheel: pip install scikit-build-core pybind11" >&2
    "$PYTHON" -m pip install -q "scikit-build-core>=0.10" "pybind11>=2.10"
  fi
  # No build isolation: use the tools installed above (no index access needed at build time)
  # and keep the CMake build directory for incremental rebuilds.
  "$PYTHON" -m pip wheel . --no-deps --no-build-isolation -q -w "$WHEEL_DIR" \
    --config-settings=build-dir=build-wheel
else
  ext_suffix=$("$PYTHON" -c "import sysconfig; print(sysconfig.get_config_var('EXT_SUFFIX'))")
  module="$from_build/relief_snake_core$ext_suffix"
  if [ ! -f "$module" ]; then
    echo "build-wheel: $module is missing: build the module in $from_build for $PYTHON" \
         "(cmake -DPython3_EXECUTABLE=$(command -v "$PYTHON") ... --target relief_snake_core)" >&2
    exit 1
  fi
  build_type=$(sed -n 's/^CMAKE_BUILD_TYPE:[A-Z]*=//p' "$from_build/CMakeCache.txt" 2>/dev/null || true)
  if [ "$build_type" != "Release" ]; then
    echo "build-wheel: $from_build is a '${build_type:-unknown}' build; package from a Release build" >&2
    exit 1
  fi
  if ! command -v patchelf >/dev/null 2>&1; then
    echo "build-wheel: apt-get install patchelf" >&2
    SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO="sudo"
    $SUDO apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends patchelf
  fi
  # The libOpenMeshCore the module was linked against, under the name the module asks for.
  soname=$(readelf -d "$module" | sed -n 's/.*(NEEDED).*\[\(libOpenMeshCore[^]]*\)\].*/\1/p')
  lib=$(ldd "$module" | awk -v n="$soname" '$1 == n { print $3 }')
  if [ -z "$soname" ] || [ ! -f "$lib" ]; then
    echo "build-wheel: cannot find the libOpenMeshCore that $module links (NEEDED '$soname', ldd '$lib')" >&2
    exit 1
  fi
  root=$(mktemp -d)
  trap 'rm -rf "$root"' EXIT
  mkdir -p "$root/relief_snake_core.libs"
  cp "$module" "$root/"
  cp "$(readlink -f "$lib")" "$root/relief_snake_core.libs/$soname"
  patchelf --set-rpath '$ORIGIN/relief_snake_core.libs' "$root/$(basename "$module")"
  "$PYTHON" - "$root" "$WHEEL_DIR" "$from_build" <<'PY'
import base64, hashlib, os, sys, sysconfig, tomllib, zipfile

root, out_dir, build = sys.argv[1:4]
with open("pyproject.toml", "rb") as f:
    project = tomllib.load(f)["project"]
name, version = project["name"], project["version"]
# The module's tag: CPython <major><minor>, the ABI of its suffix, the platform.
ext = sysconfig.get_config_var("EXT_SUFFIX")            # .cpython-311-x86_64-linux-gnu.so
abi = "cp" + ext.split(".")[1].split("-")[1]           # cp311
py = "cp%d%d" % sys.version_info[:2]
plat = sysconfig.get_platform().replace("-", "_").replace(".", "_")
tag = "%s-%s-%s" % (py, abi, plat)

# The module must be this version of relief_snake_core and import with this Python.
sys.path.insert(0, root)
import relief_snake_core
if relief_snake_core.__version__ != version:
    sys.exit("build-wheel: %s has relief_snake_core %s, pyproject.toml says %s: rebuild it"
             % (build, relief_snake_core.__version__, version))

info = "%s-%s.dist-info" % (name, version)
os.makedirs(os.path.join(root, info))
meta = ["Metadata-Version: 2.1", "Name: " + name, "Version: " + version, "Summary: " + project["description"]]
lic = project.get("license")
if isinstance(lic, dict):
    lic = lic.get("text")
if lic:
    meta.append("License: " + lic)
meta += ["Classifier: " + c for c in project.get("classifiers", [])]
meta.append("Requires-Python: " + project["requires-python"])
files = {
    info + "/METADATA": "\n".join(meta) + "\n\n",
    info + "/WHEEL": "Wheel-Version: 1.0\nGenerator: relief_snake scripts/build-wheel.sh --from-build\n"
                     "Root-Is-Purelib: false\nTag: %s\n\n" % tag,
}
for rel, text in files.items():
    with open(os.path.join(root, rel), "w") as f:
        f.write(text)

record, paths = [], []
for d, _, names in os.walk(root):
    for n in names:
        paths.append(os.path.relpath(os.path.join(d, n), root))
paths.sort(key=lambda p: (p.startswith(info), p))  # payload first, .dist-info last
for rel in paths:
    data = open(os.path.join(root, rel), "rb").read()
    digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
    record.append("%s,sha256=%s,%d" % (rel, digest, len(data)))
record.append(info + "/RECORD,,")
with open(os.path.join(root, info, "RECORD"), "w") as f:
    f.write("\n".join(record) + "\n")
paths.append(info + "/RECORD")

wheel = os.path.join(out_dir, "%s-%s-%s.whl" % (name, version, tag))
with zipfile.ZipFile(wheel, "w", zipfile.ZIP_DEFLATED) as z:
    for rel in paths:
        z.write(os.path.join(root, rel), rel)
PY
fi

wheel=$(ls "$WHEEL_DIR"/relief_snake_core-*-"$py_tag"-*.whl)

# --- the truthful platform tag (auditwheel show) ---------------------------------------------
TOOLS=${WHEEL_TOOLS_VENV:-.venv-wheeltools}
if [ ! -x "$TOOLS/bin/auditwheel" ]; then
  echo "build-wheel: pip install auditwheel into $TOOLS" >&2
  "$PYTHON" -m venv "$TOOLS"
  for i in 1 2 3; do "$TOOLS/bin/python" -m pip install -q auditwheel && break; sleep 10; done
fi
policy=$("$TOOLS/bin/auditwheel" show "$wheel" 2>/dev/null \
  | tr '\n' ' ' | sed -n 's/.*following platform tag: *"\([a-z0-9_]*\)".*/\1/p')
case "$policy" in
  manylinux_*) ;;
  *) echo "build-wheel: auditwheel finds no manylinux policy for $wheel (got '$policy'):" >&2
     "$TOOLS/bin/auditwheel" show "$wheel" >&2 || true
     exit 1 ;;
esac
"$PYTHON" - "$wheel" "$policy" <<'PY'
import base64, hashlib, os, sys, zipfile
src, policy = sys.argv[1:3]
name = os.path.basename(src)
base, plat = name[:-4].rsplit("-", 1)
if plat == policy:
    sys.exit(0)
dst = os.path.join(os.path.dirname(src), "%s-%s.whl" % (base, policy))
with zipfile.ZipFile(src) as z:
    items = [(i, z.read(i.filename)) for i in z.infolist()]
out, record_name = [], None
for info, data in items:
    if info.filename.endswith(".dist-info/WHEEL"):
        data = data.decode().replace("-" + plat + "\n", "-" + policy + "\n").encode()
    if info.filename.endswith(".dist-info/RECORD"):
        record_name = info.filename
        continue
    out.append((info.filename, data))
lines = []
for n, data in out:
    digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
    lines.append("%s,sha256=%s,%d" % (n, digest, len(data)))
lines.append(record_name + ",,")
out.append((record_name, ("\n".join(lines) + "\n").encode()))
tmp = dst + ".tmp"
with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as z:
    for n, data in out:
        z.writestr(n, data)
os.replace(tmp, dst)
os.remove(src)
PY
wheel=$(ls "$WHEEL_DIR"/relief_snake_core-*-"$py_tag"-*.whl)
# The wheel must carry libOpenMeshCore and find it through $ORIGIN, not through the system.
"$PYTHON" - "$wheel" <<'PY'
import sys, zipfile
names = zipfile.ZipFile(sys.argv[1]).namelist()
mods = [n for n in names if n.startswith("relief_snake_core.") and n.endswith(".so")]
libs = [n for n in names if n.startswith("relief_snake_core.libs/libOpenMeshCore.so")]
if not mods or not libs:
    sys.exit(f"build-wheel: {sys.argv[1]} lacks the module or the bundled libOpenMeshCore: {names}")
PY
echo "build-wheel: $wheel${from_build:+ (module from $from_build)}"
