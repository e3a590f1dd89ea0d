#!/usr/bin/env bash
# Regenerates docs/images/viewer_*.png: runs the viewer's browser test (a
# small synthetic handshake scene in headless Chromium) and keeps its
# screenshots. Usage: scripts/viewer_screenshots.sh [path/to/u4d]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
u4d="${1:-$root/build/apps/u4d}"
[ -x "$u4d" ] || { echo "no u4d binary at $u4d (build first, or pass its path)"; exit 1; }
(cd "$root/viewer" && { [ -d node_modules ] || npm ci --no-audit --no-fund; } && npm run build)
mkdir -p "$root/docs/images"
node "$root/viewer/tests/browser_test.mjs" --u4d "$u4d" --screenshots "$root/docs/images"
ls -l "$root"/docs/images/viewer_*.png
