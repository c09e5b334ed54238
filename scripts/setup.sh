#!/usr/bin/env bash
# Installs everything ms2 needs on a fresh Debian 12 machine: system packages (Mesa's software
# Vulkan for headless rendering), a Python venv in .venv with the Python tools, and the `ms2`
# Python package built from this checkout with maturin (release profile, sharing target/ with
# `cargo test --release`). Safe to run again: finished steps are skipped quickly.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$(pwd)

SUDO=""
if [ "$(id -u)" != "0" ]; then SUDO="sudo"; fi

# --- Toolchains ---------------------------------------------------------------------------------
if ! command -v cargo >/dev/null 2>&1; then
  echo "[setup] error: cargo not found. ms2 needs a Rust toolchain >= 1.90 (rustup: https://rustup.rs)" >&2
  exit 1
fi
PY=${PYTHON:-python3}
if ! "$PY" -c 'import sys; assert sys.version_info >= (3, 10)' 2>/dev/null; then
  echo "[setup] error: $PY is missing or older than Python 3.10 (set PYTHON=/path/to/python3.10+)" >&2
  exit 1
fi

# --- System packages ----------------------------------------------------------------------------
APT_PACKAGES=(mesa-vulkan-drivers libvulkan1 libegl1 libgl1-mesa-dri pkg-config)
if ! "$PY" -c 'import venv, ensurepip' >/dev/null 2>&1; then
  APT_PACKAGES+=(python3-venv)
fi
# A C compiler: rustc links with `cc`, and the Python extension compiles mimalloc (its allocator).
if ! command -v cc >/dev/null 2>&1; then
  APT_PACKAGES+=(gcc libc6-dev)
fi
missing=()
for p in "${APT_PACKAGES[@]}"; do
  dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
done
if [ "${#missing[@]}" -gt 0 ]; then
  echo "[setup] installing Debian packages: ${missing[*]}"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# --- Python venv --------------------------------------------------------------------------------
if [ ! -x .venv/bin/python ]; then
  echo "[setup] creating .venv ($("$PY" --version))"
  "$PY" -m venv .venv
fi
# shellcheck disable=SC1091
. .venv/bin/activate
# Reinstall the Python tools only when the requirements changed since the last successful run.
REQ_STAMP=.venv/.ms2-requirements.sha256
REQ_HASH=$(sha256sum scripts/requirements-dev.txt ms2-py/pyproject.toml | sha256sum | cut -d' ' -f1)
if [ ! -f "$REQ_STAMP" ] || [ "$(cat "$REQ_STAMP")" != "$REQ_HASH" ]; then
  echo "[setup] installing Python tools (scripts/requirements-dev.txt)"
  python -m pip install -q --upgrade pip
  python -m pip install -q -r scripts/requirements-dev.txt
  echo "$REQ_HASH" >"$REQ_STAMP"
fi

# --- The ms2 Python package ---------------------------------------------------------------------
# `maturin develop` runs `cargo build --release -p ms2-py` in the workspace's target/ (a no-op
# when nothing changed) and installs the package in editable mode: the Python sources in
# ms2-py/python are used in place.
echo "[setup] building the ms2 Python package (maturin develop --release)"
if [ "$(cat .venv/.ms2-installed 2>/dev/null)" = "$REQ_HASH" ]; then
  # Already installed in editable mode: rebuilding the extension in place is enough.
  (cd ms2-py && maturin develop --release --quiet --skip-install)
else
  (cd ms2-py && maturin develop --release --quiet)
  echo "$REQ_HASH" >.venv/.ms2-installed
fi
python -c 'import ms2'

# --- Fetched assets -----------------------------------------------------------------------------
# The real Panda's meshes (Franka's franka_description, Apache-2.0; never part of this repository)
# into the asset directory ($MS2_ASSET_DIR, default ~/.ms2/data): from an installed mani_skill2
# package, else the mani-skill2==0.5.3 wheel from PyPI (pip, ~12 MB, checksum-verified). A no-op
# when present and verified. Without them ms2 uses its primitive Panda (with one warning).
if ! python -m ms2 assets fetch franka_description --quiet; then
  echo "[setup] warning: could not fetch the real Panda's meshes; the primitive Panda is used." \
    "Retry with: ms2 assets fetch franka_description" >&2
fi
echo "[setup] done: activate the venv with '. $ROOT/.venv/bin/activate'"
