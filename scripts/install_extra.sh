#!/usr/bin/env bash
# Sets up the machine (scripts/setup.sh) and installs an optional extra of ms2-py/pyproject.toml
# into .venv unless its modules already import: `scripts/install_extra.sh EXTRA MODULE[,MODULE...]`
# (e.g. `ray ray`, `baselines torch,stable_baselines3`). Used by the opt-in test scripts
# (scripts/test_ray.sh, scripts/test_baselines.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
extra=$1 modules=$2
bash scripts/setup.sh >/dev/null
# shellcheck disable=SC1091
. .venv/bin/activate
if ! python -c "import ${modules}" >/dev/null 2>&1; then
  # A command substitution, not `< <(...)`, so that an unknown extra stops the script (set -e).
  reqs_text=$(EXTRA="$extra" python - <<'PY'
import os
import tomllib
with open("ms2-py/pyproject.toml", "rb") as f:
    extras = tomllib.load(f)["project"]["optional-dependencies"]
name = os.environ["EXTRA"]
if name not in extras:
    raise SystemExit(f"no extra {name!r} in ms2-py/pyproject.toml: expected one of {sorted(extras)}")
print("\n".join(extras[name]))
PY
)
  mapfile -t reqs <<<"$reqs_text"
  echo "[install_extra] installing the $extra extra: ${reqs[*]}"
  python -m pip install -q "${reqs[@]}"
fi
