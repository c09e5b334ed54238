#!/usr/bin/env bash
# The opt-in baselines smoke tests (not in scripts/test.sh, which needs no torch): installs the
# `baselines` extra of ms2-py/pyproject.toml (torch, stable-baselines3; torch from PyPI brings
# large CUDA wheels) into .venv, then runs ms2-py/tests/test_baselines.py: each script of
# ms2-py/examples/baselines/ end to end with tiny settings (a few hundred env steps) and
# SB3VecEnvWrapper under stable-baselines3's VecMonitor, PPO.learn and evaluate_policy. The same
# tests skip themselves in scripts/test.sh's pytest run wherever torch or stable-baselines3 is
# not installed. Extra pytest arguments are passed on (e.g. `-k ppo`). See docs/baselines.md.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_extra.sh baselines torch,stable_baselines3
# shellcheck disable=SC1091
. .venv/bin/activate
echo "[test_baselines] pytest ms2-py/tests/test_baselines.py"
RAYON_NUM_THREADS=1 python -m pytest -q ms2-py/tests/test_baselines.py "$@"
