#!/usr/bin/env bash
# Runs the clay benchmark scene with ms2-mpm and with the same MLS-MPM substep written in
# Taichi (CPU backend), back to back at equal particle count, grid and thread count, and
# prints particle-substeps per second side by side.
#
# Taichi is installed on demand into its own venv (default target/taichi-venv; override with
# MS2_TAICHI_VENV), never into the project's .venv. Needs Python 3.11 or 3.10 (PYTHON=...).
#
# Usage: ms2-mpm/bench/compare_taichi.sh            (SUBSTEPS=300 PARTICLES="32768 65536")
set -euo pipefail
cd "$(dirname "$0")/../.."
ROOT=$(pwd)
VENV=${MS2_TAICHI_VENV:-$ROOT/target/taichi-venv}
PY=${PYTHON:-python3}
SUBSTEPS=${SUBSTEPS:-300}
PARTICLES=${PARTICLES:-"32768 65536"}
ALL=$(nproc)

if [ ! -x "$VENV/bin/python" ]; then
  echo "[bench] creating $VENV" >&2
  "$PY" -m venv "$VENV"
fi
if ! "$VENV/bin/python" -c "import taichi" >/dev/null 2>&1; then
  echo "[bench] installing taichi 1.7.4 into $VENV" >&2
  "$VENV/bin/python" -m pip install -q "taichi==1.7.4"
fi
echo "[bench] building ms2-mpm (release)" >&2
cargo build --release -q -p ms2-mpm --example bench_step
MS2="$ROOT/target/release/examples/bench_step"
TAICHI=("$VENV/bin/python" "$ROOT/ms2-mpm/bench/taichi_mls_mpm.py")

field() { # field NAME LINE
  tr ' ' '\n' <<<"$2" | sed -n "s/^$1=//p"
}

# top_z: height (m) of the block's top after the run, from each engine: the same physics.
printf '%-10s %-8s %-22s %-22s %-7s %s\n' particles threads "ms2-mpm (p·substep/s)" \
  "taichi (p·substep/s)" ratio "top_z ms2 / taichi (m)"
for n in $PARTICLES; do
  for t in 1 "$ALL"; do
    ours=$("$MS2" "$n" "$t" "$SUBSTEPS")
    theirs=$("${TAICHI[@]}" "$n" "$t" "$SUBSTEPS" 2>/dev/null | grep '^engine=')
    a=$(field particle_substeps_per_s "$ours")
    b=$(field particle_substeps_per_s "$theirs")
    ratio=$(awk -v a="$a" -v b="$b" 'BEGIN { printf "%.2f", a / b }')
    printf '%-10s %-8s %-22s %-22s %-7s %s / %s\n' "$n" "$t" "$a" "$b" "${ratio}x" \
      "$(field top_z "$ours")" "$(field top_z "$theirs")"
    if [ "$t" = "$ALL" ] && [ "$ALL" = 1 ]; then break; fi
  done
done
