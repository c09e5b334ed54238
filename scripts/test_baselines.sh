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
bash scripts/setup.sh >/dev/null
# shellcheck disable=SC1091
. .venv/bin/activate
mapfile -t BASELINES_REQS < <(python - <<'PY'
import tomllib
with open("ms2-py/pyproject.toml", "rb") as f:
    print("\n".join(tomllib.load(f)["project"]["optional-dependencies"]["baselines"]))
PY
)
if ! python -c 'import torch, stable_baselines3' >/dev/null 2>&1; then
  echo "[test_baselines] installing the baselines extra: ${BASELINES_REQS[*]}"
  python -m pip install -q "${BASELINES_REQS[@]}"
fi
echo "[test_baselines] pytest ms2-py/tests/test_baselines.py"
RAYON_NUM_THREADS=1 python -m pytest -q ms2-py/tests/test_baselines.py "$@"
