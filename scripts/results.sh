#!/usr/bin/env bash
# Regenerates docs/results.md: builds the benchmark targets and `u4d`, then
# scripts/results/runner.py runs every benchmark in bench/ one after the other
# (each step's output and provenance as files in a work folder) and
# scripts/results/render.py assembles the document from them, section by
# section in the order of the paper's evaluation (Sec. 4), each with the exact
# command, the machine, the date and the wall time that produced it.
#
#   scripts/results.sh [--quick] [--only a,b,...] [--out FILE] [--update]
#                      [--no-build] [--keep] [--reuse DIR]
#                      [--speed-views "4 8"] [--speed-sizes "480x270 960x540"]
#                      [--speed-frames N] [--length-frames "30 100 300"]
#                      [--scale-sizes "480x270 960x540"] [--long-frames N]
#
# Run from anywhere; works in the repository root. The build directory is
# $BUILD (default `build`), configured as Release if it does not exist.
#   --quick         small sizes, to check the script end to end (8-11 min
#                   of benches on a shared 2-core machine, plus the build); the
#                   default runs the sizes docs/*.md quote (about an hour there).
#   --only LIST     run only these sections (comma separated ids: seg, depth,
#                   flow, camera_flow, fusion, pose, sparse, tracks, keyframes,
#                   mrf, synth, speed; seg/depth/flow share one joint_bench run).
#                   Real-data sections: middlebury, sintel.
#                   The realistic world's initial masks against a real
#                   detector's ranges, on held-out seeds: detector.
#                   The joint solve on the realistic world: realistic.
#                   Kernel throughput and the joint solve's phases: kernels.
#                   Long sequences: long (--long-frames).
#                   End to end: scenarios (handshake, meetup, moving cameras;
#                   S_e of DeepFlow/DIS/Farneback vs GT), ablations (`u4d run
#                   --ablation`), scaling (views 4/8/16, image sizes up to
#                   1080p; plot with python3-matplotlib when installed),
#                   true_masks (the realistic world and the handshake with
#                   their true masks, default and trusted-mask settings).
#   --out FILE      write FILE (relative to the repository root) instead of
#                   docs/results.md.
#   --update        with --only: replace only the sections this run wrote in
#                   the existing FILE (matched by heading; new ones go before
#                   "Not yet measured") and the summary's rows taken from them,
#                   keep the other sections and rows, and name the regenerated
#                   sections in the header.
#   --no-build      do not run cmake/ninja (the binaries must exist).
#   --speed-views, --speed-sizes, --speed-frames
#                   the `u4d run` speed section: one synthetic handshake per
#                   (views, size), each run through the whole pipeline.
#   --length-frames  the sequence-length section: `u4d run` on 4 views at
#                   160x90 for each of these frame counts (time per frame and
#                   peak memory must stay flat); section id: length.
#   --scale-sizes "WxH ..."  the image sizes of the scaling section's second
#                   curve (4 views; default 160x90 640x360 quick, 480x270
#                   960x540 1920x1080 full). The section also runs the
#                   speed goal of issue 7, 8 views at 960x540 (environment
#                   SCALE_GOAL="V WxH" changes it, SCALE_GOAL="" skips it).
#   --long-frames N  the long-sequence section (id: long): each scenario as
#                   one N-frame capture through `u4d run` and `u4d eval`
#                   (default 100 in both modes; about an hour at 100).
#   --keep          keep the work folder (raw outputs, captures, scenes).
#   --reuse DIR     assemble from a kept work folder: steps whose output is
#                   there are not run again (for editing the renderer,
#                   scripts/results/render.py and prose.md).
# The renderer's tests: scripts/results/test_render.py (ctest -R results_).
set -uo pipefail
cd "$(dirname "$0")/.." || exit 1

BUILD=${BUILD:-build}
DO_BUILD=1
args=("$@")
while [[ $# -gt 0 ]]; do
  case "$1" in
    --no-build) DO_BUILD=0 ;;
    --reuse) DO_BUILD=0; shift ;;
    --only | --out | --speed-* | --length-frames | --long-frames | --scale-sizes) shift ;;
    --quick | --update | --keep) ;;
    -h | --help) sed -n '2,/^set -uo/p' "$0" | sed '$d' | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "results.sh: unknown option '$1' (see --help)" >&2; exit 2 ;;
  esac
  shift
done

BENCHES=(sparse_bench tracks_bench shelf_pose_bench keyframes_bench depth_cost_bench
  flow_cost_bench camera_flow_bench joint_bench fusion_bench mrf_bench synth_bench synth_render_bench u4d
  middlebury_bench sintel_bench kernels_bench joint_phases_bench)
if [[ $DO_BUILD == 1 ]]; then
  if [[ ! -f $BUILD/build.ninja ]]; then
    cmake -S . -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null || exit 1
  fi
  echo "[results $(date +%H:%M:%S)] building ${BENCHES[*]} in $BUILD" >&2
  log=$(mktemp "${TMPDIR:-/tmp}/u4d_results_build.XXXXXX")
  if ! ninja -C "$BUILD" -j"$(nproc)" "${BENCHES[@]}" >"$log" 2>&1; then
    tail -40 "$log" >&2
    echo "results.sh: build failed (log above)" >&2
    exit 1
  fi
  rm -f "$log"
fi
BUILD=$BUILD exec python3 scripts/results/runner.py "${args[@]}"
