#!/usr/bin/env bash
# Installs everything ms2 needs on a fresh Debian 12 machine: system packages (Mesa's software
# Vulkan for headless rendering), a Python venv in .venv with the Python tools, and the `ms2`
# Python package built from this checkout with maturin. Safe to run again: finished steps are
# skipped quickly.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$(pwd)

SUDO=""
if [ "$(id -u)" != "0" ]; then SUDO="sudo"; fi

# --- System packages -------------------------------------------------------------------------
APT_PACKAGES=(mesa-vulkan-drivers libvulkan1 libegl1 libgl1-mesa-dri pkg-config)
missing=()
for p in "${APT_PACKAGES[@]}"; do
  dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
done
if [ "${#missing[@]}" -gt 0 ]; then
  echo "[setup] installing Debian packages: ${missing[*]}"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${missing[@]}"
fi

# --- Python venv -----------------------------------------------------------------------------
PY=${PYTHON:-python3}
if [ ! -x .venv/bin/python ]; then
  echo "[setup] creating .venv"
  "$PY" -m venv .venv
fi
# shellcheck disable=SC1091
. .venv/bin/activate
python -m pip install -q --upgrade pip >/dev/null
python -m pip install -q -r scripts/requirements-dev.txt

# --- The ms2 Python package ------------------------------------------------------------------
if [ -f ms2-py/pyproject.toml ]; then
  echo "[setup] building the ms2 Python package (maturin, release)"
  (cd ms2-py && maturin develop --release -q)
fi
echo "[setup] done: activate with '. $ROOT/.venv/bin/activate'"
