#!/usr/bin/env bash
# The Bevy integration's tests (its own cargo workspace): unit tests, the GPU = CPU probe
# and the headless renders. The GPU tests run on whatever Vulkan adapter wgpu finds; on
# machines without a GPU that is Mesa's software rasteriser lavapipe (Debian package
# mesa-vulkan-drivers), installed here when no Vulkan driver is present.
set -euo pipefail
cd "$(dirname "$0")"

if ! ls /usr/share/vulkan/icd.d/lvp_icd.*.json >/dev/null 2>&1 \
    && ! ls /etc/vulkan/icd.d/*.json >/dev/null 2>&1 \
    && ! ls /usr/share/vulkan/icd.d/nvidia*.json >/dev/null 2>&1; then
    echo "integrations/bevy/test.sh: installing mesa-vulkan-drivers (software Vulkan)" >&2
    SUDO=""
    if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
    if ! $SUDO apt-get install -y --no-install-recommends mesa-vulkan-drivers >/dev/null; then
        $SUDO apt-get update >/dev/null
        $SUDO apt-get install -y --no-install-recommends mesa-vulkan-drivers >/dev/null
    fi
fi

cargo test --locked
