#!/usr/bin/env bash
# Builds the gvsrom CLI and the Python package into a fresh venv and runs the Python tests.
#   crates/gvsrom-py/run-tests.sh            (from anywhere; uses $CARGO_TARGET_DIR or target/)
# The venv is target/py-venv (reused if present); the tests compare with the CLI binary (GVSROM_BIN).
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
cd "$root"
target="${CARGO_TARGET_DIR:-$root/target}"
venv="$target/py-venv"
python="${PYTHON:-python3}"

# the CLI the tests compare with: `--workspace` resolves features as `cargo test --workspace` does,
# so after the tests nothing is compiled again (`-p gvsrom` alone would rebuild most dependencies)
cargo build --workspace --bins --quiet
if [ ! -x "$venv/bin/python" ]; then
    "$python" -m venv "$venv"
fi
"$venv/bin/python" -m pip install --quiet --upgrade pip
"$venv/bin/python" -m pip install --quiet "maturin>=1.9,<2" pytest numpy mypy
# `maturin develop` builds the extension (dev profile: the workspace's optimized test profile) and
# installs it into the venv
VIRTUAL_ENV="$venv" PATH="$venv/bin:$PATH" \
    "$venv/bin/maturin" develop --quiet -m crates/gvsrom-py/Cargo.toml
cd crates/gvsrom-py
GVSROM_BIN="$target/debug/gvsrom" "$venv/bin/python" -m pytest -q tests "$@"
