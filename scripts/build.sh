#!/usr/bin/env bash
# Configures and builds U4D into build/ (Release). Extra arguments go to cmake.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release "$@" >/dev/null
ninja -C build -j "${U4D_JOBS:-$(nproc)}"
