#!/usr/bin/env bash
# The main job: sets up a fresh machine (scripts/setup.sh) and runs a scripted PickCube episode,
# saved as out/PickCube-v0/episode_0.mp4 and out/PickCube-v0/PickCube-v0.h5 (+ .json),
# printing whether it succeeded. With arguments, runs `ms2 <arguments>` instead, e.g.
#   ./scripts/run.sh run StackCube-v0 --policy scripted --episodes 20
#   ./scripts/run.sh bench
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
# shellcheck disable=SC1091
. .venv/bin/activate
if [ "$#" -gt 0 ]; then
  exec ms2 "$@"
fi
exec ms2 run PickCube-v0 --policy scripted --episodes 1 --verbose --record out/PickCube-v0
