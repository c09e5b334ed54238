#!/usr/bin/env bash
# Fails when git tracks build artefacts: anything under a `target/` or `target-*/` directory at
# any depth, compiled objects and libraries (*.rlib, *.rmeta, *.o, *.a, *.so, *.dylib, *.dll,
# *.pdb, *.exe), cargo's bookkeeping (.fingerprint/, .rustc_info.json, *.d dep-info next to
# them), and Python caches (__pycache__/, *.pyc, *.pyo, .pytest_cache/, .ruff_cache/).
# Prints every offending path. Usage: scripts/check_repo.sh [REPO_DIR] (default: this checkout).
set -euo pipefail
repo=${1:-"$(dirname "$0")/.."}
cd "$repo"

artefact_re='(^|/)(target|target-[^/]*)/'
artefact_re+='|(^|/)(\.fingerprint|__pycache__|\.pytest_cache|\.ruff_cache|\.mypy_cache)/'
artefact_re+='|(^|/)\.rustc_info\.json$'
artefact_re+='|\.(rlib|rmeta|o|a|so|dylib|dll|pdb|exe|pyc|pyo|whl)$'
artefact_re+='|\.so\.[0-9.]+$'

# -z keeps odd file names intact; `git ls-files` lists what the index tracks (staged included).
bad=$(git ls-files -z | tr '\0' '\n' | grep -E "$artefact_re" || true)
if [ -n "$bad" ]; then
  n=$(printf '%s\n' "$bad" | wc -l)
  echo "check_repo: $n tracked build artefact(s); remove them with 'git rm -r --cached' and" \
    "make sure .gitignore covers them:" >&2
  printf '%s\n' "$bad" | sed 's/^/  /' >&2
  exit 1
fi
echo "check_repo: no tracked build artefacts"
