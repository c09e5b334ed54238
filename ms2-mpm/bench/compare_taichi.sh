#!/usr/bin/env bash
# Runs the clay benchmark scene with ms2-mpm and with three Taichi (CPU backend) versions of
# the same MLS-MPM substep, back to back and interleaved (ROUNDS rounds of: ms2-mpm, the
# project's straight port `taichi_mls_mpm.py`, the fair kernel `taichi_fair_mls_mpm.py` with
# ti.svd, the fair kernel with ms2-mpm's Jacobi left stretch), at equal particle count, grid
# and thread count. Prints every run, then per particle count and thread count the median
# particle-substeps per second (per particle each engine really simulated), ms2-mpm's ratio
# to each Taichi version (the median of the per-round ratios, each between runs seconds
# apart, which shared-machine load shifts less than it shifts the rates), the block's top height after the run from each engine (the same
# physics gives the same height), and the `uptime` load averages before and after.
#
# Taichi is installed on demand into its own venv (default target/taichi-venv; override with
# MS2_TAICHI_VENV), never into the project's .venv. Needs Python 3.11 or 3.10 (PYTHON=...).
#
# Usage: ms2-mpm/bench/compare_taichi.sh
#   (SUBSTEPS=300 PARTICLES="32768 65536" THREADS="1 <nproc>" ROUNDS=3
#    ENGINES="ms2 port fair-svd fair-jacobi")
set -euo pipefail
cd "$(dirname "$0")/../.."
ROOT=$(pwd)
VENV=${MS2_TAICHI_VENV:-$ROOT/target/taichi-venv}
PY=${PYTHON:-python3}
SUBSTEPS=${SUBSTEPS:-300}
PARTICLES=${PARTICLES:-"32768 65536"}
ALL=$(nproc)
THREADS=${THREADS:-$([ "$ALL" = 1 ] && echo 1 || echo "1 $ALL")}
ROUNDS=${ROUNDS:-3}
ENGINES=${ENGINES:-"ms2 port fair-svd fair-jacobi"}

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
BENCH="$ROOT/ms2-mpm/bench"

run() { # run ENGINE PARTICLES THREADS -> one key=value line
  case "$1" in
    ms2) "$ROOT/target/release/examples/bench_step" "$2" "$3" "$SUBSTEPS" ;;
    port) "$VENV/bin/python" "$BENCH/taichi_mls_mpm.py" "$2" "$3" "$SUBSTEPS" ;;
    fair-svd | fair-jacobi)
      "$VENV/bin/python" "$BENCH/taichi_fair_mls_mpm.py" "$2" "$3" "$SUBSTEPS" \
        --eigen "${1#fair-}" ;;
    *) echo "unknown engine $1 (expected ms2, port, fair-svd or fair-jacobi)" >&2; exit 2 ;;
  esac 2>/dev/null | grep '^engine='
}

field() { # field NAME LINE
  tr ' ' '\n' <<<"$2" | sed -n "s/^$1=//p"
}

load() { uptime | sed 's/.*load average: //'; }

median() { # median FORMAT "v1 v2 ..."
  tr ' ' '\n' <<<"$2" | sed '/^$/d' | sort -g |
    awk -v f="$1" '{ a[NR] = $1 } END { printf f, (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2 }'
}

echo "[bench] $(date -u '+%F %T') UTC, $(nproc) cores, load $(load), substeps $SUBSTEPS"
summary=()
for n in $PARTICLES; do
  for t in $THREADS; do
    before=$(load)
    declare -A rates=() tops=() ratios=() last=()
    for r in $(seq "$ROUNDS"); do
      for e in $ENGINES; do
        line=$(run "$e" "$n" "$t")
        echo "round=$r $line"
        last[$e]=$(field particle_substeps_per_s "$line")
        rates[$e]+="${last[$e]} "
        tops[$e]=$(field top_z "$line")
      done
      if [ -n "${last[ms2]:-}" ]; then
        for e in $ENGINES; do
          ratios[$e]+="$(awk -v a="${last[ms2]}" -v b="${last[$e]}" 'BEGIN { print a / b }') "
        done
      fi
    done
    after=$(load)
    row="particles=$n threads=$t load=[$before]..[$after]"
    for e in $ENGINES; do
      row+=" $e=$(median "%.3e" "${rates[$e]}") top_z_$e=${tops[$e]}"
    done
    for e in $ENGINES; do
      [ "$e" = ms2 ] || [ -z "${ratios[$e]:-}" ] && continue
      row+=" ms2/$e=$(median "%.2f" "${ratios[$e]}")"
    done
    summary+=("$row")
    unset rates tops ratios last
  done
done
echo "[bench] medians over $ROUNDS rounds (particle-substeps per second per real particle):"
printf '%s\n' "${summary[@]}"
