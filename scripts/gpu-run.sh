#!/usr/bin/env bash
# On the GPU machine, from the bundle scripts/gpu-bundle.sh made:
#   ./gpu-run.sh RESULTS_DIR [tests|bench|pocl|all]...      (default: all)
#   ./gpu-run.sh RESULTS_DIR exec COMMAND [ARGS...]          (COMMAND under the same setup)
# Registers NVIDIA's OpenCL driver with the ICD loader (OCL_ICD_VENDORS: a private vendors folder
# with nvidia.icd next to the machine's own .icd files, e.g. its PoCL), links from the bundle
# only the libraries the machine lacks, then
#   tests  the whole test suite with FOGCL_DEVICE=gpu, in parallel shards (gtest XML per shard)
#   bench  both benchmarks on the GPU (device-resident and host round trip, the device copy, the
#          pinned and pageable transfer of a round trip's bytes in the round trip's run)
#   pocl   the volumetric march on the machine's PoCL, 1 to all cores (POCL_MAX_PTHREAD_COUNT)
#   interop  a GPU renderer's frame where it lies, alone (not in "all"; tests and bench hold it
#          too): the interop tests, examples/vulkan_exporter.cpp at three sizes, and every row of
#          the interop bench (CUDA and Vulkan producers)
#   sequence  fogcl apply on frame sequences against OpenEXR alone (sequence_bench.py; not in
#          "all": minutes of I/O; SEQUENCE_ARGS adds its options, e.g. "--cases 4k-half-zip")
# and writes RESULTS_DIR/summary.md from what they left (gpu_summary.py).
set -uo pipefail
here=$(cd "$(dirname "$0")" && pwd)
results=${1:?usage: gpu-run.sh RESULTS_DIR [tests|bench|pocl|all]...}
shift
parts=("${@:-all}")
mkdir -p "$results"
results=$(cd "$results" && pwd)
scratch=$(mktemp -d)
want() { local p; for p in "${parts[@]}"; do [ "$p" = all ] || [ "$p" = "$1" ] && return 0; done; return 1; }

# --- OpenCL: NVIDIA's driver next to the machine's registered ICDs ------------------------------
mkdir -p "$scratch/icd"
cp /etc/OpenCL/vendors/*.icd "$scratch/icd/" 2>/dev/null
nvidia=$( (ldconfig -p | awk '/libnvidia-opencl.so.1 / {print $NF}'; ls /usr/local/nvidia/lib64/libnvidia-opencl.so.1 \
           /usr/lib/x86_64-linux-gnu/libnvidia-opencl.so.1 /usr/lib/libnvidia-opencl.so.1 2>/dev/null) | head -1)
if [ -z "$nvidia" ]; then
  echo "gpu-run: libnvidia-opencl.so.1 not found (is this the GPU machine?)" >&2
  exit 2
fi
echo "$nvidia" >"$scratch/icd/nvidia.icd"
export OCL_ICD_VENDORS="$scratch/icd"

# --- Libraries: the machine's own where it has them (a newer libstdc++ serves our binaries and
# its PoCL alike), the bundle's for the rest ---------------------------------------------------
mkdir -p "$scratch/lib"
for lib in "$here"/lib/*; do
  name=$(basename "$lib")
  ldconfig -p | grep -q "^[[:space:]]$name " || ln -s "$lib" "$scratch/lib/$name"
done
export LD_LIBRARY_PATH="$scratch/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"

# --- Vulkan: its loader and GLVND from the bundle (gl/*.deb) where the machine has none; the
# interop tests and bench take their shared semaphores from Vulkan (CUDA makes none to export) --
if ! ldconfig -p | grep -q "libvulkan.so.1 " && ls "$here"/gl/*.deb >/dev/null 2>&1; then
  for deb in "$here"/gl/*.deb; do dpkg -x "$deb" /; done
  ldconfig
fi
for icd in /usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json /usr/share/vulkan/icd.d/nvidia_icd.json; do
  [ -e "$icd" ] && { export VK_DRIVER_FILES="$icd"; break; }
done

{
  echo "commit: $(cat "$here/COMMIT" 2>/dev/null)"
  echo "date: $(date -u +%FT%TZ)"
  echo "host: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
  nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader 2>/dev/null | sed 's/^/gpu: /'
  echo "OCL_ICD_VENDORS: $(ls "$scratch/icd" | tr '\n' ' ')"
  echo "bundled libraries used: $(ls "$scratch/lib" | tr '\n' ' ')"
} | tee "$results/machine.txt"

bin="$here/bin"
status=0
if [ "${parts[0]}" = exec ]; then
  "${parts[@]:1}"
  status=$?
  rm -rf "$scratch"
  exit $status
fi

# --- The whole suite on the GPU ------------------------------------------------------------------
mkdir -p "$scratch/tests"
test_env=(FOGCL_DEVICE=gpu FOGCL_TEST_CLI="$bin/fogcl" FOGCL_TEST_CUDA_INTEROP="$bin/fogcl_cuda_interop"
          FOGCL_TEST_VULKAN_EXPORTER="$bin/fogcl_vulkan_exporter" FOGCL_TEST_CALL_GATE="$bin/fogcl_call_gate.so"
          FOGCL_TEST_DIR="$scratch/tests"
          FOGCL_TEST_PLOTS_OPTIONAL=1)  # nothing can be installed there: no matplotlib, the plot tests skip
if want tests; then
  shards=${GPU_TEST_SHARDS:-8}
  echo "tests: fogcl_tests with FOGCL_DEVICE=gpu in $shards shards"
  start=$(date +%s)
  for i in $(seq 0 $((shards - 1))); do
    env "${test_env[@]}" GTEST_TOTAL_SHARDS=$shards GTEST_SHARD_INDEX=$i timeout "${GPU_TEST_TIMEOUT:-540}" "$bin/fogcl_tests" \
      --gtest_output="xml:$results/tests-$i.xml" >"$results/tests-$i.log" 2>&1 &
  done
  wait
  echo "tests: $(( $(date +%s) - start )) s"
fi

# --- Benchmarks on the GPU -----------------------------------------------------------------------
bench() {  # bench BINARY JSON FILTER [args...]
  "$bin/$1" --benchmark_out_format=json --benchmark_out="$results/$2" --benchmark_filter="$3" "${@:4}" \
    >"$results/${2%.json}.txt" 2>&1 || { echo "bench: $1 $3 failed (see ${2%.json}.txt)"; status=1; }
}
if want bench; then
  echo "bench: deferred pass on the GPU"
  FOGCL_DEVICE=gpu bench fogcl_bench fog-gpu.json \
    'BM_DeviceCopy|BM_OpenCLDevice/w:(1920|3840)/h:(1080|2160)/.*/nt:2|BM_OpenCLHostCall/w:(1920|3840)|BM_OpenCLHostCallPinned|BM_PinnedTransfer|BM_DispatchOverhead|BM_FirstDispatch|BM_ProgramBuild' \
    --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
  echo "bench: volumetric pass on the GPU"
  FOGCL_DEVICE=gpu bench fogcl_volume_bench volume-gpu.json 'BM_VolumeDevice|BM_VolumeHostCall|BM_VolumeNothingVisible' \
    --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
  bench fogcl_volume_bench volume-scalar.json 'BM_VolumeScalar'
  echo "bench: a CUDA or Vulkan producer's frame fogged in its memory, signal to signal"
  FOGCL_DEVICE=gpu bench fogcl_interop_bench interop-gpu.json 'BM_ExternalSignalToSignal|BM_VulkanSignalToSignal'
fi

# --- PoCL on every core: the volumetric march from 1 thread to all -----------------------------
if want pocl; then
  cores=$(nproc)
  for t in 1 2 4 8 16 32 64; do
    [ "$t" -le "$cores" ] || break
    echo "pocl: $t threads"
    FOGCL_DEVICE=cpu POCL_MAX_PTHREAD_COUNT=$t bench fogcl_volume_bench "volume-pocl-$t.json" \
      'BM_VolumeDevice/integrator:[01]/divisor:2/noise_image:0/width:1920' --benchmark_repetitions=3 \
      --benchmark_report_aggregates_only=true
  done
fi

# --- A GPU renderer's frame where it lies ------------------------------------------------------
if [ "${parts[0]}" = interop ]; then
  echo "interop: the interop tests, the Vulkan exporter example, the hand-over rows"
  env "${test_env[@]}" timeout 300 "$bin/fogcl_tests" --gtest_filter='GpuInterop*:ExternalInterop*' \
    >"$results/interop-tests.txt" 2>&1 || { echo "interop: tests failed (see interop-tests.txt)"; status=1; }
  for size in "" "1920 1080" "3840 2160"; do
    echo "\$ vulkan_exporter $size"
    # shellcheck disable=SC2086
    FOGCL_DEVICE=gpu timeout 120 "$bin/fogcl_vulkan_exporter" $size
    code=$?
    echo "exit status $code"
    [ $code -eq 0 ] || status=1
  done >"$results/vulkan-exporter.txt" 2>&1
  FOGCL_DEVICE=gpu bench fogcl_interop_bench interop-gpu.json '.'
fi

# --- Frame sequences: OpenEXR alone against fogcl apply, N threads pinned to N cores ----------
if [ "${parts[0]}" = sequence ]; then
  # shellcheck disable=SC2086
  python3 "$here/sequence_bench.py" --bin "$bin" --out "$results/sequence" --data "$scratch/sequences" --pin \
    ${SEQUENCE_ARGS:-} >"$results/sequence.txt" 2>&1 || { echo "sequence: failed (see sequence.txt)"; status=1; }
  tail -n 40 "$results/sequence.txt"
fi

python3 "$here/gpu_summary.py" "$results" >"$results/summary.md" || status=1
cat "$results/summary.md"
rm -rf "$scratch"
grep -q "^FAILED" "$results/summary.md" && status=1
exit $status
