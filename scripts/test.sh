#!/usr/bin/env bash
# The whole test suite (the README's test command). Installs what the tests need first:
# the GPU tests run on whatever Vulkan adapter wgpu finds, and on machines without a GPU
# that is Mesa's software rasteriser lavapipe (Debian package mesa-vulkan-drivers); the
# engine shader libraries (shaders/glsl, shaders/hlsl) are compiled by glslangValidator
# (Debian package glslang-tools).
set -euo pipefail
cd "$(dirname "$0")/.."

if ! ls /usr/share/vulkan/icd.d/lvp_icd.*.json >/dev/null 2>&1 \
    && ! ls /etc/vulkan/icd.d/*.json >/dev/null 2>&1 \
    && ! ls /usr/share/vulkan/icd.d/nvidia*.json >/dev/null 2>&1; then
    echo "scripts/test.sh: installing mesa-vulkan-drivers (software Vulkan for the GPU tests)" >&2
    SUDO=""
    if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
    if ! $SUDO apt-get install -y --no-install-recommends mesa-vulkan-drivers >/dev/null; then
        $SUDO apt-get update >/dev/null
        $SUDO apt-get install -y --no-install-recommends mesa-vulkan-drivers >/dev/null
    fi
fi

if ! command -v glslangValidator >/dev/null 2>&1; then
    echo "scripts/test.sh: installing glslang-tools (glslangValidator for the engine shader libraries)" >&2
    SUDO=""
    if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
    if ! $SUDO apt-get install -y --no-install-recommends glslang-tools >/dev/null; then
        $SUDO apt-get update >/dev/null
        $SUDO apt-get install -y --no-install-recommends glslang-tools >/dev/null
    fi
fi

cargo test --workspace --locked

# The Python package: a fresh virtual environment, `pip install ./python`, pytest.
bash scripts/test_python.sh
