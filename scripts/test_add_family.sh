#!/usr/bin/env bash
# Heavy check (not in CI; run by hand: 4 min on 2 idle cores with target/ warm): a task family added as a folder plus
# its one registration call, and nothing else, is reachable from `gym.make` and `ms2 run`.
#
# Copies this checkout to a temporary directory, drops the throwaway family of
# tests/tests/throwaway_family/ into ms2-tasks/src/families/throwaway/, adds its `mod` line and
# its `register` call to families/mod.rs, builds the Python package there (sharing this
# checkout's target/ for dependencies) into a throwaway venv, and runs the family's env through
# gymnasium and the CLI with its scripted policy.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$(pwd)
bash scripts/setup.sh >/dev/null
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
echo "[add-family] copying the checkout to $WORK"
mkdir -p "$WORK/src"
git ls-files -z --cached --others --exclude-standard | tar --null -T - -cf - | tar -xf - -C "$WORK/src"
FAMILIES="$WORK/src/ms2-tasks/src/families"
cp -r tests/tests/throwaway_family "$FAMILIES/throwaway"
# The one registration call (and the module it names); no other file is touched.
python3 - "$FAMILIES/mod.rs" <<'PY'
import sys
path = sys.argv[1]
s = open(path).read()
s = s.replace("pub mod rigid;\n", "pub mod rigid;\npub mod throwaway;\n", 1)
s = s.replace("    dummy::register(r);\n", "    dummy::register(r);\n    throwaway::register(r);\n", 1)
open(path, "w").write(s)
PY
git diff --no-index --stat "$ROOT/ms2-tasks/src/families" "$FAMILIES" || true
echo "[add-family] building the Python package with the new family"
python3 -m venv --system-site-packages "$WORK/venv"
# shellcheck disable=SC1091
. "$WORK/venv/bin/activate"
pip install -q maturin
(cd "$WORK/src/ms2-py" && CARGO_TARGET_DIR="$ROOT/target" maturin develop --release --quiet)
cd "$WORK"
python - <<'PY'
import gymnasium as gym
import ms2

assert "ReachGoal-v0" in ms2.env_ids(), ms2.env_ids()
env = gym.make("ReachGoal-v0", obs_mode="state")
obs, info = env.reset(seed=0)
policy = ms2.ScriptedPolicy(env)
policy.reset()
for _ in range(100):
    obs, reward, terminated, truncated, info = env.step(policy.act())
    if terminated or truncated:
        break
assert info["success"], info
print("[add-family] gym.make('ReachGoal-v0') solved by its scripted policy:", info)
PY
ms2 run ReachGoal-v0 --policy scripted --episodes 3 --verbose
echo "[add-family] passed"
