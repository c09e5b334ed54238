#!/usr/bin/env bash
# Checks that every library crate can be published to crates.io on its own: `cargo package`
# assembles each crate's .crate file (only what lies inside the crate directory, with the
# normalized manifest and Cargo.lock) and, where verified, builds it from the unpacked tarball,
# so an `include_str!` of a file outside the crate, a README path or a build script reading a
# sibling would fail here. Sibling ms2 crates are not on crates.io: since cargo 1.90,
# `cargo package --workspace` / several `-p` resolve them through a local overlay registry built
# from the crates being packaged, so a crate must be packaged together with its ms2 dependencies.
#
# Verification builds in the dev profile (`cargo package` takes no profile, and the workspace's
# profile settings do not apply to the unpacked crates), so it compiles the dependencies again
# in target/debug; debug info and incremental data are switched off below to keep that short.
# Two steps, to bound CI time on a 2-core runner:
# 1. every library crate is packaged (manifest normalized, files listed, README found,
#    siblings resolved through the overlay) without building: `--no-verify`;
# 2. the crates whose dependency graphs are light enough are packaged again and built from
#    their .crate files. Left unverified: ms2-render and ms2-tasks, whose builds would add
#    wgpu/naga/image (and, for ms2-tasks, every other crate) to a second full dev-profile build
#    of the workspace's dependencies. Neither reads files outside its directory at build time
#    (ms2-render's one `include_str!` is `src/shader.wgsl`; ms2-tasks has none, no build
#    scripts anywhere), which is what verification would catch.
set -euo pipefail
cd "$(dirname "$0")/.."

# Not published: the pyo3 extension and the cross-crate integration tests (`publish = false`).
excluded=(--exclude ms2-py --exclude ms2-integration-tests)
# --allow-dirty: this is a check that the crates package and build, not a release; local runs
# of scripts/test.sh usually have uncommitted changes.
export CARGO_PROFILE_DEV_DEBUG=0 CARGO_INCREMENTAL=0

# The overlay's crates keep their version (0.1.0), and cargo reuses a crate it once extracted
# under ~/.cargo/registry/src for the same name and version: a machine that ran this check
# before would verify against the old sources. Drop those extractions of our own crates (they
# never come from crates.io).
cargo_home="${CARGO_HOME:-$HOME/.cargo}"
# The same holds for their builds in target/debug, fingerprinted by name, version and source,
# not by content.
for stale in "$cargo_home"/registry/src/*/ms2-*-0.1.0 "$cargo_home"/registry/cache/*/ms2-*-0.1.0.crate \
  target/debug/.fingerprint/ms2-* target/debug/deps/libms2_* target/debug/deps/ms2_*; do
  [ -e "$stale" ] && rm -rf "$stale"
done
echo "[packages] cargo package --no-verify: every library crate"
cargo package --workspace "${excluded[@]}" --allow-dirty --locked --no-verify
# A crate must be listed with its ms2 dependencies (they come from the overlay, not crates.io).
echo "[packages] cargo package, verified: ms2-assets, ms2-mpm, ms2-physics, ms2-control, ms2-plan"
cargo package -p ms2-assets -p ms2-mpm -p ms2-physics -p ms2-control -p ms2-plan \
  --allow-dirty --locked
