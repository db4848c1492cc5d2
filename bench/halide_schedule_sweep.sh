#!/usr/bin/env bash
# The Halide peer's schedule exploration (bench/halide_peer.cpp, FOGCL_HALIDE_SCHEDULE): every
# schedule given runs BM_Halide on the same rows in its own process, the schedules in turn, ROUNDS
# rounds, so that a busy or drifting machine moves them alike. One JSON per schedule and round.
#   bench/halide_schedule_sweep.sh OUT_DIR ROUNDS FILTER SCHEDULE...
# e.g. bench/halide_schedule_sweep.sh out/sweep 3 'BM_Halide/w:1920/h:1080/mode:[02]/dist:[01]/f16:0/' \
#        'vec=16' 'vec=8' 'vec=32' 'vec=16,rows=8'
# Then: python3 bench/halide_schedule_sweep.py OUT_DIR (medians per schedule and row).
set -euo pipefail
out=$1 rounds=$2 filter=$3
shift 3
bench=${BENCH:-build/bench/fogcl_bench}
mkdir -p "$out"
printf '%s\n' "$@" >"$out/schedules.txt"
export POCL_MAX_PTHREAD_COUNT=2
for round in $(seq 1 "$rounds"); do
  i=0
  for schedule in "$@"; do
    FOGCL_HALIDE_SCHEDULE="$schedule" "$bench" --benchmark_filter="$filter" --benchmark_format=json \
      >"$out/s$i-r$round.json" 2>/dev/null
    i=$((i + 1))
  done
done
