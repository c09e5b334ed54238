#!/usr/bin/env bash
# The opt-in Ray tests (not in scripts/test.sh; ~1.5 min on 2 cores once set up): installs the
# `ray` extra of ms2-py/pyproject.toml into .venv, then runs ms2-py/tests/test_ray.py with
# MS2_TEST_RAY=1: a Ray cluster of separate processes on 127.0.0.1 (head + two worker nodes),
# `ms2 demos generate --ray` with a worker node killed mid-run (files identical to a local
# run's), `ms2 evaluate --ray`, and examples/ray_rollouts.py. Extra pytest arguments are passed
# on (e.g. `-k killed`). See docs/ray.md.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_extra.sh ray ray
# shellcheck disable=SC1091
. .venv/bin/activate
echo "[test_ray] pytest ms2-py/tests/test_ray.py (MS2_TEST_RAY=1)"
MS2_TEST_RAY=1 RAYON_NUM_THREADS=1 python -m pytest -q ms2-py/tests/test_ray.py "$@"
