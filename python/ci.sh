#!/usr/bin/env bash
# The Python package's CI (called by .ci/run): builds and installs it with
# pip in a fresh virtual environment, then runs its pytest tests, which
# compare it with the `shaping` command line (built here if SHAPING_BIN is
# not set); checks the type stubs with mypy's stubtest and runs bench.py
# once. Exits non-zero if the build, the install, stubtest, a test or the
# bench fails.
#
#   bash python/ci.sh
set -euo pipefail
cd "$(dirname "$0")/.."

# The binding crate is its own workspace: format and lints here (the root's
# `cargo fmt --all` and `cargo clippy --workspace` do not see it).
cargo fmt --manifest-path python/Cargo.toml --check
cargo clippy --quiet --manifest-path python/Cargo.toml --all-targets -- -D warnings

python="${PYTHON:-python3}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
"$python" -m venv "$work/venv"
venv="$work/venv/bin"

# maturin (from PyPI, in pip's isolated build environment) builds the
# extension in release; CARGO_TARGET_DIR, if set, is reused.
"$venv/pip" install --quiet --disable-pip-version-check "./python[test]"

if [ -z "${SHAPING_BIN:-}" ]; then
  cargo build --quiet --bin shaping
  target="$(cargo metadata --format-version 1 --no-deps \
    | "$python" -c 'import json, sys; print(json.load(sys.stdin)["target_directory"])')"
  export SHAPING_BIN="$target/debug/shaping"
fi

root="$(pwd)"

# The type stubs against the installed module (mypy's stubtest).
"$venv/pip" install --quiet --disable-pip-version-check mypy
(cd "$work" && "$venv/python" -m mypy.stubtest shaping)

# Run from outside the source tree, so `import shaping` is the installed package.
cd "$work"
CI="${CI:-}" "$venv/python" -m pytest "$root/python/tests" -q -p no:cacheprovider

# The bench as its documentation runs it, from the repository's root (where
# python/ holds no package source to shadow the installed package): one
# round, to see that it runs; its ratios are not checked.
cd "$root"
"$venv/python" python/bench.py --rounds 1
