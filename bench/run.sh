#!/usr/bin/env bash
# Runs the benchmark suite and renders its plot.
#   bench/run.sh [BUILD_DIR] [OUT_DIR]     (defaults: build, out/bench)
# Writes OUT_DIR/fog.json (every path, PoCL with 2 threads), OUT_DIR/pocl1.json (the OpenCL device
# benchmarks again with POCL_MAX_PTHREAD_COUNT=1), OUT_DIR/start-cold.json and start-warm.json
# (process start to first frame, empty and filled PoCL kernel cache) and OUT_DIR/throughput.png.
set -euo pipefail
build=${1:-build}
out=${2:-out/bench}
bench="$build/bench/fogcl_bench"
mkdir -p "$out"
json() { "$bench" --benchmark_out_format=json --benchmark_out="$1" "${@:2}"; }

export POCL_MAX_PTHREAD_COUNT=2
json "$out/fog.json" --benchmark_filter='-BM_StartToFirstFrame' --benchmark_repetitions=3 \
  --benchmark_report_aggregates_only=true
POCL_MAX_PTHREAD_COUNT=1 json "$out/pocl1.json" --benchmark_filter='BM_OpenCLDevice|BM_Memcpy' \
  --benchmark_repetitions=3 --benchmark_report_aggregates_only=true

cold_cache=$(mktemp -d)
POCL_CACHE_DIR="$cold_cache" json "$out/start-cold.json" --benchmark_filter='BM_StartToFirstFrame'
POCL_CACHE_DIR="$cold_cache" json "$out/start-warm.json" --benchmark_filter='BM_StartToFirstFrame'
rm -rf "$cold_cache"

/usr/bin/python3 "$(dirname "$0")/plot.py" "$out"
