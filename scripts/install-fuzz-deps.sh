#!/usr/bin/env bash
# Installs what `make fuzz` needs: clang with libFuzzer and the ASan/UBSan runtimes (Debian).
# Idempotent: it only calls apt-get when something is missing; waits for the dpkg lock.
set -euo pipefail

APT_PACKAGES=(clang libclang-rt-dev)

missing=()
for pkg in "${APT_PACKAGES[@]}"; do
  dpkg -s "$pkg" >/dev/null 2>&1 || missing+=("$pkg")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "install-fuzz-deps: apt-get install ${missing[*]}" >&2
  SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get -o DPkg::Lock::Timeout=600 update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get -o DPkg::Lock::Timeout=600 install -y -qq --no-install-recommends "${missing[@]}"
fi

# atheris (PyPI) for the module's argument-handling harness (fuzz/atheris_module.py).
PYTHON=${PYTHON:-python3}
if ! "$PYTHON" -c "import atheris" >/dev/null 2>&1; then
  echo "install-fuzz-deps: pip install atheris" >&2
  "$PYTHON" -m pip install -q atheris
fi
