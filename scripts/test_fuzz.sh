#!/usr/bin/env bash
# A smoke run of every fuzz target (fuzz/README.md): SECONDS seconds each (default 30), the
# last step of scripts/test.sh. The targets build with cargo-fuzz on the stable toolchain
# (`-s none`: libFuzzer's coverage instrumentation, no sanitizer, no nightly flag).
# cargo-fuzz comes from crates.io, pinned so that a cached ~/.cargo/bin is reused;
# libFuzzer itself is C++ and needs a C++ compiler (Debian package g++, installed here when
# missing).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-30}

if ! command -v c++ >/dev/null 2>&1; then
    echo "scripts/test_fuzz.sh: installing g++ (libFuzzer is built from C++ sources)" >&2
    SUDO=""
    if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
    if ! $SUDO apt-get install -y --no-install-recommends g++ >/dev/null; then
        $SUDO apt-get update >/dev/null
        $SUDO apt-get install -y --no-install-recommends g++ >/dev/null
    fi
fi
if [ "$(cargo fuzz --version 2>/dev/null)" != "cargo-fuzz 0.13.2" ]; then
    cargo install cargo-fuzz --version 0.13.2 --locked
fi
bash fuzz/run.sh "$seconds"
