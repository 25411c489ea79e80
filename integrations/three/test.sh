#!/usr/bin/env bash
# The browser tests of @nacre/three (test/run.mjs): Debian's Chromium driven by playwright-core,
# WebGL 2 on SwiftShader, three.js r187 (newest on npm) and r160 (oldest supported); and
# WebGPURenderer on Chromium's WebGPU over SwiftShader (Debian's chromium ships
# libvk_swiftshader.so), r187 and r171 (oldest supported there).
# Installs what it needs: apt `chromium` when /usr/bin/chromium is missing (root or sudo), the
# npm packages from package-lock.json (`npm ci`). Needs Node.js ≥ 20 and npm (Debian 12's
# nodejs is 18: install 20 or newer). Like every step of scripts/test.sh it fails, never
# skips, when something is missing; only the glTF screenshot skips outside CI when
# ../shared/gltf-samples is absent (a user's clone does not have it).
set -euo pipefail
cd "$(dirname "$0")"
start=$(date +%s)

missing() {
    echo "integrations/three/test.sh: FAIL: $1" >&2
    exit 1
}

if ! command -v node >/dev/null 2>&1 || ! command -v npm >/dev/null 2>&1; then
    missing "node and npm are needed (Node.js ≥ 20)"
fi
if [ "$(node -p 'process.versions.node.split(".")[0]')" -lt 20 ]; then
    missing "Node.js $(node --version) is older than 20 (playwright-core needs ≥ 20)"
fi

chromium_bin="${NACRE_CHROMIUM:-/usr/bin/chromium}"
if [ ! -x "$chromium_bin" ]; then
    SUDO=""
    if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
    echo "integrations/three/test.sh: installing chromium (apt; $chromium_bin is missing)" >&2
    if ! $SUDO apt-get install -y --no-install-recommends chromium >/dev/null; then
        $SUDO apt-get update >/dev/null
        $SUDO apt-get install -y --no-install-recommends chromium >/dev/null
    fi
    [ -x "$chromium_bin" ] || missing "$chromium_bin still missing after installing chromium"
fi

npm ci --no-audit --no-fund --loglevel=error
node scripts/gen-glsl.mjs --check
node test/run.mjs
echo "integrations/three/test.sh: $(( $(date +%s) - start )) s"
