#!/usr/bin/env bash
# The main job: set up, build, then `u4d demo` (synthesise a capture, run the
# whole pipeline on it, evaluate against the ground truth, print a summary)
# into out/demo; `./build/apps/u4d view out/demo/scene` shows the result.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash scripts/build.sh
export OMP_WAIT_POLICY=passive
./build/apps/u4d demo -o "${1:-out/demo}"
