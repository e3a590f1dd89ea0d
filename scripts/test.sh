#!/usr/bin/env bash
# The test command: set up, build, run the whole GoogleTest suite with ctest.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash scripts/build.sh
export OMP_WAIT_POLICY=passive
cd build
ctest --output-on-failure -j "${U4D_JOBS:-$(nproc)}" --timeout 900
