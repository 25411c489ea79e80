#!/usr/bin/env bash
# The browser tests of @nacre/three (test/run.mjs): Debian's Chromium driven by playwright-core,
# WebGL 2 on SwiftShader, three.js r187 (newest on npm) and r160 (oldest supported).
# Installs what it needs: apt `chromium` when /usr/bin/chromium is missing (root or sudo), the
# npm packages from package-lock.json (`npm ci`). Needs Node.js ≥ 20 and npm.
# Outside CI a missing tool is a clear SKIP; in CI (env CI set) it is a failure.
set -euo pipefail
cd "$(dirname "$0")"
start=$(date +%s)

missing() {
    if [ -n "${CI:-}" ]; then
        echo "integrations/three/test.sh: FAIL: $1" >&2
        exit 1
    fi
    echo "integrations/three/test.sh: SKIP (not in CI): $1" >&2
    exit 0
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
    if [ -n "${CI:-}" ] || [ "${NACRE_INSTALL_CHROMIUM:-}" = 1 ]; then
        echo "integrations/three/test.sh: installing chromium (apt)" >&2
        if ! $SUDO apt-get install -y --no-install-recommends chromium >/dev/null; then
            $SUDO apt-get update >/dev/null
            $SUDO apt-get install -y --no-install-recommends chromium >/dev/null
        fi
    else
        missing "$chromium_bin not found (apt install chromium, or NACRE_INSTALL_CHROMIUM=1)"
    fi
fi

npm ci --no-audit --no-fund --loglevel=error
node scripts/gen-glsl.mjs --check
node test/run.mjs
echo "integrations/three/test.sh: $(( $(date +%s) - start )) s"
