#!/usr/bin/env bash
# Sets up a fresh machine (scripts/setup.sh) and runs every test: Rust (workspace) and Python.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
# shellcheck disable=SC1091
. .venv/bin/activate
echo "[test] cargo test (workspace, release profile)"
cargo test --release --workspace --exclude ms2-py
if [ -d ms2-py/tests ]; then
  echo "[test] pytest"
  python -m pytest -q ms2-py/tests
fi
