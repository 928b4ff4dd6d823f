#!/usr/bin/env bash
# Installs the two Blenders the add-on is tested in, idempotently:
#  - Debian's Blender 3.4 (apt, Python 3.11, no numpy) for `blender --background`;
#  - bpy 4.2.x LTS from PyPI in .venv-bpy (python3.11 venv; bpy 4.2 wheels are cp311 only) + pytest.
# Re-running does nothing when both are already there.
set -euo pipefail
cd "$(dirname "$0")/.."

if ! command -v blender >/dev/null 2>&1; then
  echo "install-blender: apt-get install blender" >&2
  SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq blender
fi

VENV=${VENV_BPY:-.venv-bpy}
PY311=${PY311:-$(command -v python3.11 || true)}
if [ -z "$PY311" ]; then
  echo "install-blender: python3.11 is required for bpy 4.2 (its wheels are cp311 only); install python3.11 and retry" >&2
  exit 1
fi
if [ ! -x "$VENV/bin/python" ]; then
  echo "install-blender: creating $VENV with $PY311" >&2
  "$PY311" -m venv "$VENV"
fi
if ! "$VENV/bin/python" -c "import bpy, pytest, sys; sys.exit(0 if bpy.app.version[:2] == (4, 2) else 1)" >/dev/null 2>&1; then
  # Newest 4.2.* LTS that the index offers (pip index versions lists newest first).
  BPY_VERSION=${BPY_VERSION:-$("$VENV/bin/python" -m pip index versions bpy 2>/dev/null \
      | sed -n 's/^Available versions: //p' | tr ',' '\n' | tr -d ' ' | grep -E '^4\.2\.' | head -1)}
  if [ -z "$BPY_VERSION" ]; then
    echo "install-blender: no bpy 4.2.* found on the package index; set BPY_VERSION=4.2.x and retry" >&2
    exit 1
  fi
  echo "install-blender: pip install bpy==$BPY_VERSION pytest into $VENV" >&2
  "$VENV/bin/python" -m pip install -q --upgrade pip
  "$VENV/bin/python" -m pip install -q "bpy==$BPY_VERSION" pytest
fi
echo "install-blender: $(blender --version 2>/dev/null | head -1); bpy $("$VENV/bin/python" -c 'import bpy; print(bpy.app.version_string)' 2>/dev/null | tail -1) in $VENV"
