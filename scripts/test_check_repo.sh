#!/usr/bin/env bash
# Tests scripts/check_repo.sh on throw-away git repositories: a clean one must pass, and each kind
# of tracked artefact must make it fail and be named in its report.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

new_repo() {
  rm -rf "$tmp/repo"
  mkdir -p "$tmp/repo/src"
  git -C "$tmp/repo" init -q
  echo 'fn main() {}' >"$tmp/repo/src/main.rs"
  # Look-alikes that are NOT artefacts: a source file named like a directory we reject, a
  # `targets` directory, a .rs file with "target" in its name.
  mkdir -p "$tmp/repo/targets" "$tmp/repo/docs"
  echo x >"$tmp/repo/targets/list.txt"
  echo x >"$tmp/repo/src/target.rs"
  echo x >"$tmp/repo/docs/notes.d.md"
  # -f: the artefacts must be tracked even if a global gitignore would hide them.
  git -C "$tmp/repo" add -f .
}

fails=0
new_repo
if ! out=$(bash "$here/check_repo.sh" "$tmp/repo" 2>&1); then
  echo "FAIL: check_repo.sh rejected a clean repository:"; echo "$out"; fails=1
fi

for artefact in \
  ms2-physics/examples/target/release/deps/libfoo-0123.rlib \
  target/release/.fingerprint/foo/lib-foo \
  crate/target-ci/debug/foo.d \
  src/foo.rmeta \
  build/foo.o \
  python/ms2/_native.cpython-311-x86_64-linux-gnu.so \
  python/ms2/__pycache__/env.cpython-311.pyc \
  .rustc_info.json; do
  new_repo
  mkdir -p "$tmp/repo/$(dirname "$artefact")"
  echo junk >"$tmp/repo/$artefact"
  git -C "$tmp/repo" add -f "$artefact"
  if out=$(bash "$here/check_repo.sh" "$tmp/repo" 2>&1); then
    echo "FAIL: check_repo.sh accepted tracked artefact $artefact"; fails=1
  elif ! grep -qF "  $artefact" <<<"$out"; then
    echo "FAIL: check_repo.sh did not name $artefact:"; echo "$out"; fails=1
  fi
done
if [ "$fails" != 0 ]; then exit 1; fi
echo "test_check_repo: ok"
