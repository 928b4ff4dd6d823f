#!/usr/bin/env bash
# Installs what the engine, CLI, Python module and native tests need.
# Idempotent: it only calls apt-get/pip when something is missing.
set -euo pipefail

APT_PACKAGES=(build-essential cmake pkg-config libopenmesh-dev libeigen3-dev
              libgtest-dev pybind11-dev nlohmann-json3-dev
              libopenexr-dev libpng-dev)

missing=()
for pkg in "${APT_PACKAGES[@]}"; do
  dpkg -s "$pkg" >/dev/null 2>&1 || missing+=("$pkg")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "install-deps: apt-get install ${missing[*]}" >&2
  SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -o DPkg::Lock::Timeout=600 -y -qq --no-install-recommends "${missing[@]}"
fi

PYTHON=${PYTHON:-python3}
if ! "$PYTHON" -c "import pytest, pybind11" >/dev/null 2>&1; then
  echo "install-deps: pip install pytest pybind11" >&2
  "$PYTHON" -m pip install -q pytest pybind11
fi

# relief-snake batch (docs/batch.md): Dask for --dask and tqdm for the progress bar (pyproject's "batch" extra).
if ! "$PYTHON" -c "import dask.distributed, tqdm" >/dev/null 2>&1; then
  echo "install-deps: pip install dask[distributed] tqdm" >&2
  "$PYTHON" -m pip install -q "dask[distributed]>=2024.1" "tqdm>=4.60"
fi
