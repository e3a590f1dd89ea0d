#!/usr/bin/env bash
# The test command: set up, build, run the whole GoogleTest suite with ctest.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
# Warnings are errors here (and so in CI, .ci/run): a new warning fails the build.
bash scripts/build.sh -DU4D_WERROR=ON
export OMP_WAIT_POLICY=passive
cd build
ctest --output-on-failure -j "${U4D_JOBS:-$(nproc)}" --timeout 900
