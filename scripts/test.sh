#!/usr/bin/env bash
# Sets up a fresh machine (scripts/setup.sh) and runs every test: Rust (the workspace, release
# profile, sharing target/ with the maturin build setup.sh made) and Python (ruff + pytest), after
# the style gates CI enforces: rustfmt and clippy with warnings as errors. It starts with the
# repository hygiene check (no tracked build artefacts) and ends with `cargo package` of every
# library crate (scripts/check_packages.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
started=$(date +%s)
echo "[test] repository hygiene (no tracked build artefacts; the check's own test)"
bash scripts/check_repo.sh
bash scripts/test_check_repo.sh
bash scripts/setup.sh
# shellcheck disable=SC1091
. .venv/bin/activate
echo "[test] cargo fmt --check and clippy (workspace, all targets, warnings are errors)"
cargo fmt --all -- --check
cargo clippy --workspace --all-targets -- -D warnings
echo "[test] ms2-physics without its rapier engine (--no-default-features: the engine-neutral vocabulary)"
cargo clippy -p ms2-physics --no-default-features --all-targets -- -D warnings
echo "[test] cargo test (workspace, release profile)"
cargo test --release --workspace --exclude ms2-py
echo "[test] ruff (ms2-py)"
ruff check ms2-py
echo "[test] pytest (ms2-py/tests)"
python -m pytest -q ms2-py/tests
echo "[test] cargo package (every library crate packaged and built from its .crate alone)"
bash scripts/check_packages.sh
echo "[test] all tests passed in $(($(date +%s) - started)) s"
