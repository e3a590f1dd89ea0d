#!/usr/bin/env bash
# Builds the unit tests of the lower modules (util, geometry, io, mrf) with
# AddressSanitizer and UndefinedBehaviorSanitizer (-DU4D_SANITIZE=ON) into
# build-asan/ and runs them; any finding fails the test that met it and the
# script. The higher modules' tests (synth, joint, pipeline, ...) render or
# solve whole frames and are left to the ordinary build (scripts/test.sh).
#   scripts/sanitize.sh [TEST...]     (default: all of the list below)
set -euo pipefail
cd "$(dirname "$0")/.."
all=(util_file_test util_data_dir_test util_json_checked_test util_options_test geometry_test
  io_test io_import_test io_coco_test io_poses_test io_scene_index_test io_mesh_sequence_test
  io_output_dir_test io_fuzz_regressions_test mrf_max_flow_test mrf_expansion_test)
if [ $# -gt 0 ]; then tests=("$@"); else tests=("${all[@]}"); fi

launcher=()
command -v ccache >/dev/null 2>&1 && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
start=$(date +%s)
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DU4D_SANITIZE=ON \
  -DU4D_BUILD_BENCH=OFF -DU4D_WERROR=ON "${launcher[@]}" >/dev/null
ninja -C build-asan -j "${U4D_JOBS:-$(nproc)}" "${tests[@]}"
echo "sanitize: built ${#tests[@]} test programs in $(($(date +%s) - start)) s"

export ASAN_OPTIONS="abort_on_error=1:detect_leaks=1:strict_string_checks=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
export OMP_WAIT_POLICY=passive
failed=()
for t in "${tests[@]}"; do
  bin=$(find build-asan/src -name "$t" -type f -perm -u+x | head -1)
  t0=$(date +%s)
  if "$bin" --gtest_brief=1 >"build-asan/$t.log" 2>&1; then
    echo "sanitize: $t passed ($(($(date +%s) - t0)) s)"
  else
    echo "sanitize: $t FAILED (build-asan/$t.log):"
    grep -E 'ERROR|runtime error|SUMMARY|FAILED' "build-asan/$t.log" | head -5 || true
    failed+=("$t")
  fi
done
if [ ${#failed[@]} -gt 0 ]; then
  echo "sanitize: failed: ${failed[*]}"
  exit 1
fi
echo "sanitize: ${#tests[@]} test programs passed under ASan and UBSan"
