#!/usr/bin/env bash
# Sets up a fresh machine (scripts/setup.sh) and runs every test: Rust (the workspace, release
# profile, sharing target/ with the maturin build setup.sh made) and Python (ruff + pytest), after
# the style gates CI enforces: rustfmt, clippy and rustdoc with warnings as errors. It starts
# with the repository hygiene check (no tracked build artefacts) and ends with `cargo package` of
# every library crate (scripts/check_packages.sh).
#
# `scripts/test.sh --heavy` (or MS2_HEAVY_TESTS=1) also runs the long pytest sweeps CI leaves
# out to stay within its ~30 min on 2 cores (ms2-py/tests/conftest.py `HEAVY`): more scripted
# soft-task episodes, every mode of the slowest soft tasks, longer restores, hypothesis's
# "heavy" profile.
set -euo pipefail
cd "$(dirname "$0")/.."
for arg in "$@"; do
  case "$arg" in
    --heavy) export MS2_HEAVY_TESTS=1 ;;
    *) echo "usage: scripts/test.sh [--heavy] (got '$arg')" >&2; exit 2 ;;
  esac
done
if [ "${MS2_HEAVY_TESTS:-0}" != "0" ] && [ -n "${MS2_HEAVY_TESTS:-}" ]; then
  echo "[test] heavy: the long pytest sweeps too (MS2_HEAVY_TESTS=$MS2_HEAVY_TESTS)"
fi
started=$(date +%s)
# Seconds per stage, printed at the end (and on failure), so that CI's log tail shows where
# its time went.
stage_names=(); stage_secs=(); stage_name="start"; stage_started=$started
stage() {
  local now; now=$(date +%s)
  stage_names+=("$stage_name"); stage_secs+=($((now - stage_started)))
  stage_name="$1"; stage_started=$now
}
print_stage_times() {
  local status=$?
  stage "end"
  echo "[test] seconds per stage (exit status $status):"
  for i in "${!stage_names[@]}"; do
    printf '[test]   %6d  %s\n' "${stage_secs[$i]}" "${stage_names[$i]}"
  done
}
trap print_stage_times EXIT
# A build from scratch needs several GB of disk (less without the release profile's line tables,
# which CI drops: CARGO_PROFILE_RELEASE_DEBUG=0); say so up front rather than failing mid-link.
free_kb=$(df -Pk . | awk 'NR == 2 {print $4}')
echo "[test] free disk here: $((free_kb / 1024 / 1024)) GB"
if [ "$free_kb" -lt $((8 * 1024 * 1024)) ]; then
  echo "[test] warning: less than 8 GB free; a build from scratch may stop with 'No space left on device'" >&2
fi
stage "repository hygiene"
echo "[test] repository hygiene (no tracked build artefacts; the check's own test)"
bash scripts/check_repo.sh
bash scripts/test_check_repo.sh
stage "setup (apt, venv, wheel build)"
bash scripts/setup.sh
stage "apt packages for the viewer tests"
# The viewer's tests (ms2-py/tests/test_viewer.py, test_teleop.py) open windows on a virtual X
# server and drive them with synthetic key and mouse events; the leaderboard's test
# (test_leaderboard.py) screenshots its HTML page in headless Chromium.
TEST_APT_PACKAGES=(xvfb xdotool chromium)
missing=()
for p in "${TEST_APT_PACKAGES[@]}"; do
  dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
done
if [ "${#missing[@]}" -gt 0 ]; then
  echo "[test] installing Debian packages for the viewer and leaderboard tests: ${missing[*]}"
  SUDO=""; if [ "$(id -u)" != "0" ]; then SUDO="sudo"; fi
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
# shellcheck disable=SC1091
. .venv/bin/activate
stage "fmt + clippy"
echo "[test] cargo fmt --check and clippy (workspace, all targets, warnings are errors)"
cargo fmt --all -- --check
cargo clippy --workspace --all-targets -- -D warnings
stage "cargo doc"
echo "[test] cargo doc (workspace crates, broken intra-doc links are errors)"
RUSTDOCFLAGS="-D warnings" cargo doc --no-deps --workspace --exclude ms2-py
stage "clippy ms2-physics --no-default-features"
echo "[test] ms2-physics without its rapier engine (--no-default-features: the engine-neutral vocabulary)"
cargo clippy -p ms2-physics --no-default-features --all-targets -- -D warnings
stage "cargo test (workspace, release)"
echo "[test] cargo test (workspace, release profile)"
# Libraries, binaries, integration tests and examples marked `test = true`, then the doc tests.
# The other examples are not built again in release here: clippy --all-targets above compiles
# and lints every one of them, and no test runs an example binary (about 50 release links).
cargo test --release --workspace --exclude ms2-py --lib --bins --tests
stage "doc tests"
cargo test --release --workspace --exclude ms2-py --doc
stage "vendored rapier3d tests"
echo "[test] the vendored rapier3d's patches: kernels bit for bit, cached filter verdicts (third_party/rapier3d/PATCHES.md)"
# Not a workspace member (its own lock file and lints), so its patch tests run here.
cargo test --release --manifest-path third_party/rapier3d/Cargo.toml --lib -- \
    multibody_kernels generic_joint_constraint::tests filter_verdicts_are_cached_per_epoch \
    filtered_pairs_without_contacts_are_recycled_within_the_window \
    filtered_pairs_coming_closer_get_their_first_contact_in_time \
    filtered_and_plain_colliders_are_recycled_by_their_separating_gap unit_inverse_mass_columns_equal_fresh_solves
stage "ms2-tasks feature combinations"
echo "[test] ms2-tasks feature combinations (clippy --all-targets each; state-only tests)"
# Every feature combination of ms2-tasks must build (lints only, not builds), and the
# state-only runtime (`rapier` alone: no wgpu, no MPM, no planner) must pass its tests.
# Measured on the 2-core dev machine (load ~3, 2026-11-24), dependencies already compiled by the
# steps above so that only ms2-tasks itself is compiled per combination: 27 s for the step
# (checks 1-3 s each, the state-only release build and test run 16 s). In a cold target/ the
# same step took ~40 min there (wgpu, MPM and a release rapier build under load ~8).
# Clippy rather than check, so that each combination is linted too (17 s for the five here,
# warm).
for features in "" rapier rapier,render rapier,soft rapier,demos; do
    echo "[test]   cargo clippy -p ms2-tasks --all-targets --no-default-features --features '$features'"
    cargo clippy -q -p ms2-tasks --all-targets --no-default-features --features "$features" -- -D warnings
done
stage "ms2-tasks state-only tests"
# The state-only build's own test (`tests/state_only.rs`, which only compiles there) and the
# unit tests; the other test files run above with every feature on and compile the same code
# paths (clippy checked this combination). The stage took 580 s in a cold run with every test
# file (2026-11-29, load ~5), nearly all of it compiling: the dependencies again with the
# state-only feature set, then 20 test binaries linked in release; this keeps the first part
# and one binary. `--heavy` still runs them all.
if [ -n "${MS2_HEAVY_TESTS:-}" ] && [ "${MS2_HEAVY_TESTS}" != "0" ]; then
    state_only_tests=(--tests)
else
    state_only_tests=(--test state_only)
fi
echo "[test]   cargo test --release -p ms2-tasks --no-default-features --features rapier --lib ${state_only_tests[*]}"
cargo test --release -p ms2-tasks --no-default-features --features rapier --lib "${state_only_tests[@]}"
stage "ruff"
echo "[test] ruff (ms2-py)"
ruff check ms2-py
stage "pytest"
echo "[test] pytest (ms2-py/tests)"
# One worker process per core (pytest-xdist; PYTEST_WORKERS overrides): most tests simulate on
# one thread, so two workers use both cores; conftest.py starts the minutes-long tests first so
# that the short ones fill in around them. Two workers, niced under two other engineers' work
# (load 6-7), without --heavy: 1,093 s (2026-11-28 18:14-18:32 UTC; the longest test, Pour-v0's
# scripted episode, 539 s), where the suite with the soft tasks' full sweeps took 3,782 s at
# load 8-10 the same morning.
python -m pytest -q -n "${PYTEST_WORKERS:-auto}" --dist load ms2-py/tests
stage "cargo package"
echo "[test] cargo package (every library crate packaged and built from its .crate alone)"
bash scripts/check_packages.sh
echo "[test] all tests passed in $(($(date +%s) - started)) s"
