#!/usr/bin/env bash
# Every test the project has, in one command: the README's second set-up command, and what
# CI runs (.ci/run calls it on a fresh clone). The steps run in the order of STEPS below;
#
#   bash scripts/test.sh              # every step
#   bash scripts/test.sh rust python  # only these steps (still in STEPS order)
#
# Each step installs what it needs (Debian packages through apt-get, pinned tools through
# cargo install) and fails — never skips — when something is missing. To add a step: write
# a function step_NAME below (usually one line calling a script of its own) and add NAME
# to STEPS. docs/guide/src/testing.md describes every step.
set -euo pipefail
cd "$(dirname "$0")/.."

# The property tests (proptest) draw their cases from this fixed seed here, so that every
# run of this script checks the same cases and CI cannot fail on a draw no one has seen;
# `cargo test` alone draws new cases each run. PROPTEST_RNG_SEED=random explores.
if [ "${PROPTEST_RNG_SEED:-}" = random ]; then
    unset PROPTEST_RNG_SEED
else
    export PROPTEST_RNG_SEED="${PROPTEST_RNG_SEED:-20261204}"
fi

STEPS=(rust gl python guide bevy three fuzz)

# Debian packages, with one `apt-get update` retry (a fresh machine has no package lists).
apt_install() {
    local sudo=""
    if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
    if ! $sudo apt-get install -y --no-install-recommends "$@" >/dev/null; then
        $sudo apt-get update >/dev/null
        $sudo apt-get install -y --no-install-recommends "$@" >/dev/null
    fi
}

# The Rust workspace. The GPU tests run on whatever Vulkan adapter wgpu finds, and on
# machines without a GPU that is Mesa's software rasteriser lavapipe (Debian package
# mesa-vulkan-drivers); the engine shader libraries (shaders/glsl, shaders/hlsl) are
# compiled by glslangValidator (Debian package glslang-tools). The workspace's tests include
# the user guide's checks: every relative link and anchor of the Markdown resolves
# (tests/tests/doc_links.rs) and every command has a chapter (crates/cli/tests/guide.rs).
step_rust() {
    if ! ls /usr/share/vulkan/icd.d/lvp_icd.*.json >/dev/null 2>&1 \
        && ! ls /etc/vulkan/icd.d/*.json >/dev/null 2>&1 \
        && ! ls /usr/share/vulkan/icd.d/nvidia*.json >/dev/null 2>&1; then
        echo "scripts/test.sh: installing mesa-vulkan-drivers (software Vulkan for the GPU tests)" >&2
        apt_install mesa-vulkan-drivers
    fi
    if ! command -v glslangValidator >/dev/null 2>&1; then
        echo "scripts/test.sh: installing glslang-tools (glslangValidator for the engine shader libraries)" >&2
        apt_install glslang-tools
    fi
    # nacre studio's window test (crates/studio/tests/window.rs) runs `nacre-studio` under
    # Xvfb: xvfb-run and xauth, and the X libraries winit opens at run time.
    if ! command -v xvfb-run >/dev/null 2>&1 || ! command -v xauth >/dev/null 2>&1 \
        || ! have_library libX11-xcb.so.1 || ! have_library libxkbcommon-x11.so.0 \
        || ! have_library libXcursor.so.1 || ! have_library libXrandr.so.2 \
        || ! have_library libXi.so.6; then
        echo "scripts/test.sh: installing xvfb and X libraries (nacre studio's window test)" >&2
        apt_install xvfb xauth libx11-xcb1 libxkbcommon-x11-0 libxcursor1 libxrandr2 libxi6
    fi
    slangpy_venv
    cargo test --workspace --locked
}

# Whether the dynamic linker knows library $1 (grep reads to the end: an early exit would
# fail the pipe under pipefail).
have_library() {
    { ldconfig -p 2>/dev/null || /sbin/ldconfig -p; } | grep -F "$1" >/dev/null
}

# Slang from PyPI's slangpy (pinned), in a virtual environment under target/ kept between runs,
# for tests/tests/hlsl_slang.rs (the engine HLSL compiled by a second HLSL compiler; neither
# DXC nor FXC installs on Linux from the registries). Its first install takes about 20 s
# (a 289 MB package); later runs reuse it. NACRE_SLANGPY_PYTHON already set: used as it is.
SLANGPY_VERSION=0.43.1
slangpy_venv() {
    if [ -n "${NACRE_SLANGPY_PYTHON:-}" ]; then return; fi
    local venv="${CARGO_TARGET_DIR:-$PWD/target}/slangpy-venv"
    if ! "$venv/bin/python" -c "import slangpy, sys; sys.exit(slangpy.__version__ != '$SLANGPY_VERSION')" >/dev/null 2>&1; then
        if ! python3 -c 'import venv, ensurepip' >/dev/null 2>&1; then
            apt_install python3-venv
        fi
        local start
        start=$(date +%s)
        rm -rf "$venv"
        python3 -m venv "$venv"
        "$venv/bin/python" -m pip install --quiet "slangpy==$SLANGPY_VERSION"
        echo "scripts/test.sh: slangpy $SLANGPY_VERSION installed in $((  $(date +%s) - start )) s ($venv)" >&2
    fi
    export NACRE_SLANGPY_PYTHON="$venv/bin/python"
}

# The GL pass: the GPU test binaries again, on wgpu's OpenGL backend (WGPU_BACKEND=gl: Mesa's
# llvmpipe through EGL, Debian packages libegl1, libegl-mesa0 and libgl1-mesa-dri). After
# the Rust step: the same binaries (`--workspace --locked`), so nothing is rebuilt. Their
# GPU context fails, never skips, when wgpu finds no GL adapter. One test thread: wgpu's GL
# backend serialises every call on one context and panics when a thread waits more than 6 s
# for it (wgpu-hal's CONTEXT_LOCK_TIMEOUT_SECS), which a long llvmpipe compile in another
# test exceeds. MESA_EXTENSION_OVERRIDE lists GL_ARB_color_buffer_float, as the nacre binary
# does (crates/cli/src/gpu.rs): RGBA32F targets are core in desktop GL 3.0, but wgpu believes
# only the extension list.
GL_TESTS=(
    # crates/runtime/tests (diffraction: 18 s on GL here)
    diffraction diffraction_footprint diffraction_integrated diffraction_light diffraction_rough gltf gltf_basisu gltf_samples ktx2_load lost_device render rough
    # tests/tests
    engine_shaders_gpu gpu_probe grating_equation
    # crates/cli/tests that render (gltf_sweep: the 48 Khronos samples under ../shared, one
    # `nacre render` child each; 38 s on GL here)
    bad_input cli gltf_sweep render_rough
)
step_gl() {
    if ! ls /usr/share/glvnd/egl_vendor.d/*mesa*.json >/dev/null 2>&1 \
        || ! ls /usr/lib/*/dri/swrast_dri.so >/dev/null 2>&1; then
        echo "scripts/test.sh: installing libegl1 libegl-mesa0 libgl1-mesa-dri (Mesa's OpenGL for the GL pass)" >&2
        apt_install libegl1 libegl-mesa0 libgl1-mesa-dri
    fi
    if ! command -v glslangValidator >/dev/null 2>&1; then
        apt_install glslang-tools
    fi
    MESA_EXTENSION_OVERRIDE=+GL_ARB_color_buffer_float WGPU_BACKEND=gl \
        cargo test --workspace --locked "${GL_TESTS[@]/#/--test=}" -- --test-threads=1
}

# The Python package: a fresh virtual environment, `pip install ./python`, pytest. After
# the Rust step, whose `nacre` binary (target/debug/nacre) checks the committed CLI fixtures.
step_python() {
    bash scripts/test_python.sh
}

# The user guide: `mdbook build docs/guide` with a pinned mdBook (its links are checked by
# the Rust step).
step_guide() {
    bash scripts/test_guide.sh
}

# The Bevy integration (a cargo workspace of its own, integrations/bevy/). In CI the
# workspace's build is not needed any more (each later step has its own cargo workspace and
# target folder): its disk is freed first, as the Bevy build needs as much.
step_bevy() {
    if [ -n "${CI:-}" ] && [ -z "${CARGO_TARGET_DIR:-}" ]; then
        rm -rf target
    fi
    bash integrations/bevy/test.sh
}

# The three.js package (integrations/three, Node.js): browser tests in Debian's Chromium on
# SwiftShader against nacre's CPU colours; installs chromium (apt) and its npm packages
# (`npm ci`) itself; never skips in CI. About 3 min from a cold npm cache (its author's figure).
step_three() {
    bash integrations/three/test.sh
}

# A 30-second smoke run of every fuzz target (fuzz/README.md).
step_fuzz() {
    bash scripts/test_fuzz.sh 30
}

selected=("$@")
for name in "${selected[@]}"; do
    if ! [[ " ${STEPS[*]} " == *" $name "* ]]; then
        echo "scripts/test.sh: unknown step \`$name\` (the steps: ${STEPS[*]})" >&2
        exit 2
    fi
done
for name in "${STEPS[@]}"; do
    if [ ${#selected[@]} -gt 0 ] && ! [[ " ${selected[*]} " == *" $name "* ]]; then
        continue
    fi
    echo "scripts/test.sh: step $name" >&2
    start=$(date +%s)
    "step_$name"
    echo "scripts/test.sh: step $name passed in $(($(date +%s) - start)) s" >&2
done
