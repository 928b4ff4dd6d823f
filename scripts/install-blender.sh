#!/usr/bin/env bash
# Installs the Blenders the add-on is tested in, idempotently:
#  - Debian's Blender 3.4 (apt, Python 3.11, no numpy) for `blender --background` and, with
#    Xvfb + xdotool (apt), for the real-window tests (tests/blender/ui/);
#  - bpy 4.5 LTS from PyPI in .venv-bpy45 (Python 3.11; bpy 4.5 wheels are cp311 only) + pytest;
#  - bpy 5.2 LTS from PyPI in .venv-bpy52 (Python 3.13; bpy 5.x wheels are cp313 only) + pytest.
# Re-running does nothing when everything is there. apt-get waits for the dpkg lock (other
# jobs on a shared machine use apt too) and every network step is retried.
#
#   ONLY=apt|bpy45|bpy52   install just one part (scripts/package.sh uses ONLY=bpy52)
set -euo pipefail
cd "$(dirname "$0")/.."

SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO="sudo"
APT=(env DEBIAN_FRONTEND=noninteractive $SUDO apt-get -o DPkg::Lock::Timeout=600 -y -qq)

retry() {  # retry N cmd...: up to N attempts, 10 s apart
  local n=$1 i; shift
  for ((i = 1; i <= n; i++)); do
    "$@" && return 0
    echo "install-blender: attempt $i/$n failed: $*" >&2
    [ "$i" -lt "$n" ] && sleep 10
  done
  return 1
}

want() { [ -z "${ONLY:-}" ] || [ "$ONLY" = "$1" ]; }

# --- Debian: blender, Xvfb, xdotool, ImageMagick's import (screenshots) --------------------
if want apt; then
  missing=()
  command -v blender >/dev/null 2>&1 || missing+=(blender)
  command -v Xvfb >/dev/null 2>&1 || missing+=(xvfb)
  command -v xdotool >/dev/null 2>&1 || missing+=(xdotool)
  command -v xwd >/dev/null 2>&1 || missing+=(x11-apps)
  if [ ${#missing[@]} -gt 0 ]; then
    echo "install-blender: apt-get install ${missing[*]}" >&2
    retry 3 $SUDO apt-get -o DPkg::Lock::Timeout=600 update -qq
    retry 3 "${APT[@]}" install --no-install-recommends "${missing[@]}"
  fi
fi

# --- bpy from PyPI ---------------------------------------------------------------------------
pyenv_python() {  # pyenv_python 3.13 -> a python3.13 executable, or empty
  local v=$1 p
  p=$(command -v "python$v" 2>/dev/null || true)
  if [ -n "$p" ] && "$p" -c "import sys" >/dev/null 2>&1; then echo "$p"; return; fi
  for p in /root/.pyenv/versions/"$v".*/bin/python"$v" "$HOME"/.pyenv/versions/"$v".*/bin/python"$v"; do
    [ -x "$p" ] && { echo "$p"; return; }
  done
}

bpy_venv() {  # bpy_venv VENV PYTHON_VERSION BPY_SERIES (e.g. .venv-bpy52 3.13 5.2)
  local venv=$1 pyv=$2 series=$3 py version
  if [ -x "$venv/bin/python" ] && "$venv/bin/python" - "$series" >/dev/null 2>&1 <<'PY'
import sys, bpy, pytest
sys.exit(0 if "%d.%d" % bpy.app.version[:2] == sys.argv[1] else 1)
PY
  then return 0; fi
  py=$(pyenv_python "$pyv")
  if [ -z "$py" ]; then
    echo "install-blender: python$pyv is required for bpy $series (its wheels are cp${pyv/./} only); install it and retry" >&2
    return 1
  fi
  [ -x "$venv/bin/python" ] || { echo "install-blender: creating $venv with $py" >&2; "$py" -m venv "$venv"; }
  # Newest $series.* that the index offers (pip index versions lists newest first).
  version=$(retry 3 "$venv/bin/python" -m pip index versions bpy 2>/dev/null \
      | sed -n 's/^Available versions: //p' | tr ',' '\n' | tr -d ' ' | grep -E "^${series//./\\.}\." | head -1 || true)
  if [ -z "$version" ]; then
    echo "install-blender: no bpy $series.* found on the package index for python$pyv" >&2
    return 1
  fi
  echo "install-blender: pip install bpy==$version pytest into $venv" >&2
  retry 3 "$venv/bin/python" -m pip install -q --upgrade pip
  retry 3 "$venv/bin/python" -m pip install -q "bpy==$version" pytest
}

if want bpy45; then bpy_venv "${VENV_BPY45:-.venv-bpy45}" 3.11 4.5; fi
if want bpy52; then bpy_venv "${VENV_BPY52:-.venv-bpy52}" 3.13 5.2; fi

report() {
  local v=$1
  [ -x "$v/bin/python" ] && echo "bpy $("$v/bin/python" -c 'import bpy; print(bpy.app.version_string)' 2>/dev/null | tail -1) in $v"
  return 0
}
echo "install-blender: $(blender --version 2>/dev/null | head -1 || echo 'no blender'); $(report "${VENV_BPY45:-.venv-bpy45}"); $(report "${VENV_BPY52:-.venv-bpy52}")"
