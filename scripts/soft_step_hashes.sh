#!/usr/bin/env bash
# Fingerprints of every soft-body task's simulation: seed 0's scripted episode of each task,
# a fixed number of env steps on one thread (`examples/soft_step_cost.rs`), printing the hash
# of the final state and observation and the hash of every step's reward and info. Run it on
# two builds (e.g. before and after a solver change that must not change results) and diff the
# outputs: equal hashes mean bit-identical simulations. Also prints ms per env step (wall).
#
#   scripts/soft_step_hashes.sh > after.txt     # about 1-2 min on an idle 2-core machine
#   SOFT_STEP_COST=/path/to/old/soft_step_cost scripts/soft_step_hashes.sh > before.txt
set -euo pipefail
cd "$(dirname "$0")/.."
BIN=${SOFT_STEP_COST:-}
if [ -z "$BIN" ]; then
    cargo build --release -q -p ms2-tasks --example soft_step_cost
    BIN="${CARGO_TARGET_DIR:-target}/release/examples/soft_step_cost"
fi
# Steps per task: Pinch's and Fill's seed-0 episodes end by then; the others are slow.
for spec in "Pinch-v0 70" "Fill-v0 60" "Excavate-v0 40" "Write-v0 12" "Hang-v0 12" "Pour-v0 12"; do
    set -- $spec
    RAYON_NUM_THREADS=1 "$BIN" "$1" "$2" state 0
done
