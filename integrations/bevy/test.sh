#!/usr/bin/env bash
# The Bevy integration's tests (its own cargo workspace): unit tests, the GPU = CPU probe,
# the headless renders and the interactive viewer in a window (tests/viewer.rs). The GPU
# tests run on whatever Vulkan adapter wgpu finds; on machines without a GPU that is Mesa's
# software rasteriser lavapipe (Debian package mesa-vulkan-drivers), installed here when no
# Vulkan driver is present. The viewer's window opens on an X server without a screen
# (Xvfb, through xvfb-run), installed here with the X libraries winit loads when missing.
# Everything is built once, with the `viewer` feature (winit), so that the viewer's test
# shares the other tests' build of Bevy. A missing adapter or display fails.
set -euo pipefail
cd "$(dirname "$0")"

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
apt_install() {
    if ! $SUDO apt-get install -y --no-install-recommends "$@" >/dev/null; then
        $SUDO apt-get update >/dev/null
        $SUDO apt-get install -y --no-install-recommends "$@" >/dev/null
    fi
}

if ! ls /usr/share/vulkan/icd.d/lvp_icd.*.json >/dev/null 2>&1 \
    && ! ls /etc/vulkan/icd.d/*.json >/dev/null 2>&1 \
    && ! ls /usr/share/vulkan/icd.d/nvidia*.json >/dev/null 2>&1; then
    echo "integrations/bevy/test.sh: installing mesa-vulkan-drivers (software Vulkan)" >&2
    apt_install mesa-vulkan-drivers
fi

# Xvfb and xauth (xvfb-run), and the libraries winit opens at run time on X11.
have_library() {
    # (grep reads to the end: an early exit would fail the pipe under pipefail)
    { ldconfig -p 2>/dev/null || /sbin/ldconfig -p; } | grep -F "$1" >/dev/null
}
if ! command -v xvfb-run >/dev/null 2>&1 || ! command -v xauth >/dev/null 2>&1 \
    || ! have_library libX11-xcb.so.1 || ! have_library libxkbcommon-x11.so.0 \
    || ! have_library libXcursor.so.1 || ! have_library libXrandr.so.2 \
    || ! have_library libXi.so.6; then
    echo "integrations/bevy/test.sh: installing xvfb and X libraries (the viewer's window)" >&2
    apt_install xvfb xauth libx11-xcb1 libxkbcommon-x11-0 libxcursor1 libxrandr2 libxi6
fi

# A 24-bit screen (xvfb-run's default is 640 × 480 × 8) as large as the viewer's window.
xvfb-run -a -s "-screen 0 1280x720x24" cargo test --locked --features viewer
