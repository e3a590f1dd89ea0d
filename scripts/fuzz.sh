#!/usr/bin/env bash
# Builds the libFuzzer targets of fuzz/ with clang (-DU4D_FUZZ=ON, AddressSanitizer
# and UndefinedBehaviorSanitizer) into build-fuzz/ and runs each for SECONDS
# (default 60), from its seed corpus: fuzz/corpus/<target>/, the crash inputs
# of fuzz/regressions/<target>/ and real files from ../shared/data when present.
# Fails when any target crashes; the input is then under build-fuzz/crashes/.
#   scripts/fuzz.sh [SECONDS] [TARGET...]
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-60}"
shift || true
all=(capture calibration mask_json mask_png coco poses pfm flo mesh pc2 import_json import_text
  easymocap scene_index bvh)
if [ $# -gt 0 ]; then targets=("$@"); else targets=("${all[@]}"); fi
shared="${U4D_SHARED_DATA_DIR:-../shared/data}"
max_len=65536

launcher=()
command -v ccache >/dev/null 2>&1 && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
start=$(date +%s)
cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ \
  -DU4D_FUZZ=ON -DU4D_BUILD_TESTS=OFF -DU4D_BUILD_BENCH=OFF -DU4D_WERROR=ON "${launcher[@]}" >/dev/null
ninja -C build-fuzz -j "${U4D_JOBS:-$(nproc)}" "${targets[@]/#/fuzz_}"
echo "fuzz: built ${#targets[@]} targets in $(($(date +%s) - start)) s"

# Real files that seed a target (the first max_len bytes of each).
shared_seeds() {
  case "$1" in
    calibration | import_json) echo "$shared/shelf_pose/calibration.json \
      $shared/panoptic_demo/camera_parameters.json" ;;
    coco | poses) echo "$shared/coco_people/test_coco.json" ;;
    flo) echo "$shared/sintel_flow/clean/easy/gt/frame_0002.flo" ;;
    import_text) echo "$shared/pose2sim_multi/Calib.qca.txt $shared/dino_sparse_ring/dinoSR_par.txt \
      $shared/shelf_pose/gt.txt" ;;
    bvh) echo "$shared/mocap_cmu131/scaled_131_01.bvh" ;;
  esac
}

failed=()
for t in "${targets[@]}"; do
  corpus="build-fuzz/corpus/$t"  # grows from run to run
  crashes="build-fuzz/crashes/$t"
  scratch="build-fuzz/tmp/$t"
  mkdir -p "$corpus" "$crashes" "$scratch" "fuzz/corpus/$t" "fuzz/regressions/$t"
  for f in $(shared_seeds "$t"); do
    [ -f "$f" ] && head -c "$max_len" "$f" >"$corpus/shared_$(basename "$f")"
  done
  log="build-fuzz/$t.log"
  if TMPDIR="$PWD/$scratch" "build-fuzz/fuzz/fuzz_$t" -max_total_time="$seconds" \
    -max_len="$max_len" -rss_limit_mb=2048 -timeout=20 -print_final_stats=1 \
    -artifact_prefix="$crashes/" "$corpus" "fuzz/corpus/$t" "fuzz/regressions/$t" >"$log" 2>&1; then
    runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo '?')
    cov=$(grep -o 'cov: [0-9]* ft: [0-9]*' "$log" | tail -1)
    echo "fuzz: $t ok: $runs executions, $cov, corpus $(ls "$corpus" | wc -l) files"
  else
    echo "fuzz: $t FAILED (log $log, input in $crashes/):"
    grep -E 'ERROR|SUMMARY|what\(\)|terminate' "$log" | head -5 || true
    failed+=("$t")
  fi
  rm -rf "$scratch"
done
if [ ${#failed[@]} -gt 0 ]; then
  echo "fuzz: crashes in ${failed[*]}"
  exit 1
fi
echo "fuzz: ${#targets[@]} targets ran ${seconds} s each without a crash"
