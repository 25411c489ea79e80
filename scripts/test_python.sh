#!/usr/bin/env bash
# The Python package's tests (python/, README "Python"): a fresh virtual environment in a
# temporary folder, `pip install ./python` (a release build of the extension through
# maturin, from PyPI: maturin, numpy), then pytest on python/tests. Called by
# scripts/test.sh after the Rust tests, so that the `nacre` binary they build
# (target/debug/nacre) is there for the check that the committed CLI fixtures are current;
# runs alone as well. Needs python3 (3.9 or newer) with venv.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT="$PWD"

PYTHON="${PYTHON:-python3}"
if ! "$PYTHON" -c 'import venv, ensurepip' >/dev/null 2>&1; then
    echo "scripts/test_python.sh: installing python3-venv" >&2
    SUDO=""
    if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
    if ! $SUDO apt-get install -y --no-install-recommends python3-venv >/dev/null; then
        $SUDO apt-get update >/dev/null
        $SUDO apt-get install -y --no-install-recommends python3-venv >/dev/null
    fi
fi

VENV="$(mktemp -d "${TMPDIR:-/tmp}/nacre-python.XXXXXX")"
trap 'rm -rf "$VENV"' EXIT
start=$(date +%s)
"$PYTHON" -m venv "$VENV"
"$VENV/bin/python" -m pip install --quiet --upgrade pip
# The extension shares the workspace's target folder unless CARGO_TARGET_DIR says otherwise.
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$ROOT/target}"
# With the extra `mitsuba` (the pinned Mitsuba 3 of nacre.mitsuba), so that the plugin and
# reference tests (python/tests/test_mitsuba.py) run: NACRE_REQUIRE_MITSUBA makes them fail,
# never skip, when Mitsuba is missing.
"$VENV/bin/python" -m pip install --quiet "$ROOT/python[mitsuba]" pytest
export NACRE_REQUIRE_MITSUBA=1
# Dr.Jit's LLVM backend (Mitsuba's llvm_ad_* variants) needs a newer libLLVM than Debian
# bookworm's 14/15 (their instruction selection lacks fminimum: "LLVM ERROR: Cannot select");
# the Rust toolchain's libLLVM (22 with Rust 1.95) serves, unless DRJIT_LIBLLVM_PATH is set.
if [ -z "${DRJIT_LIBLLVM_PATH:-}" ]; then
    # Only a real shared object: the toolchain's libLLVM-*.so beside it is a 42-byte linker
    # script (INPUT(...)) that dlopen refuses.
    for lib in "$(rustc --print sysroot)"/lib/libLLVM.so.* "$(rustc --print sysroot)"/lib/libLLVM*.so*; do
        if [ -f "$lib" ] && [ "$(head -c 4 "$lib" | tail -c 3)" = "ELF" ]; then
            export DRJIT_LIBLLVM_PATH="$lib"; break
        fi
    done
fi
installed=$(date +%s)
echo "scripts/test_python.sh: pip install ./python took $((installed - start)) s" >&2

if [ -z "${NACRE_BIN:-}" ] && [ -x "$CARGO_TARGET_DIR/debug/nacre" ]; then
    export NACRE_BIN="$CARGO_TARGET_DIR/debug/nacre"
fi
# From outside the checkout, so that the installed package (not python/pysrc) is imported.
cd "$VENV"
"$VENV/bin/python" -m pytest -q -p no:cacheprovider "$ROOT/python/tests"
echo "scripts/test_python.sh: pytest took $(($(date +%s) - installed)) s" >&2
