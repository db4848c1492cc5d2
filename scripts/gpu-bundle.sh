#!/usr/bin/env bash
# Builds what the GPU machine needs and puts it in one folder to carry there.
#   scripts/gpu-bundle.sh [BUILD_DIR] [BUNDLE_DIR]      (defaults: build, out/gpu-bundle)
# The bundle: bin/ (the CLI, the test suite, the benchmarks, the sequence peer and generator, the
# CUDA and Vulkan interop examples), lib/ (every shared library they load, glibc's own excepted:
# gpu-run.sh links only those the GPU machine lacks), gpu-run.sh and gpu_summary.py. Then, on the GPU machine, from the bundle: ./gpu-run.sh RESULTS_DIR
# (docs/gpu.md).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$here")
build=${1:-build}
bundle=${2:-out/gpu-bundle}
cd "$root"

"$here/setup.sh" --bench
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" -j "$(nproc)" --target fogcl_cli fogcl_tests fogcl_bench fogcl_volume_bench \
  fogcl_exr_peer fogcl_make_sequence fogcl_cuda_interop fogcl_vulkan_exporter fogcl_call_gate \
  fogcl_interop_bench

rm -rf "$bundle"
mkdir -p "$bundle/bin" "$bundle/lib"
bins=("$build/src/fogcl" "$build/tests/fogcl_tests" "$build/bench/fogcl_bench" "$build/bench/fogcl_volume_bench"
      "$build/bench/fogcl_exr_peer" "$build/bench/fogcl_make_sequence" "$build/tests/fogcl_cuda_interop"
      "$build/tests/fogcl_vulkan_exporter"
      "$build/bench/fogcl_interop_bench" "$build/tests/fogcl_call_gate.so")
cp "${bins[@]}" "$bundle/bin/"
strip --strip-debug "$bundle"/bin/*

# glibc and the dynamic loader must be the target's own; everything else travels and gpu-run.sh
# decides per library.
ldd "${bins[@]}" | awk '/=> \// {print $3}' | sort -u | while read -r lib; do
  case "$(basename "$lib")" in
    libc.so.*|libm.so.*|libdl.so.*|libpthread.so.*|librt.so.*|ld-linux*|libgcc_s.so.*) ;;
    *) cp -L "$lib" "$bundle/lib/" ;;
  esac
done
# Vulkan's loader and GLVND for the GPU machine, which has NVIDIA's Vulkan driver but not them
# (gpu-run.sh unpacks them there): the interop tests' semaphores come from Vulkan, and
# examples/vulkan_exporter.cpp and the interop bench's Vulkan rows are a Vulkan producer.
mkdir -p "$bundle/gl"
(cd "$bundle/gl" && apt-get -oAPT::Architecture=amd64 download libvulkan1 libglvnd0 libglx0 libgl1 libegl1 \
  libopengl0 libgles2 >/dev/null 2>&1) || echo "no Vulkan loader in the bundle: the interop semaphore tests will skip"
cp "$here/gpu-run.sh" "$here/gpu_summary.py" "$root/bench/sequence_bench.py" "$bundle/"
git rev-parse --short HEAD >"$bundle/COMMIT" 2>/dev/null || echo unknown >"$bundle/COMMIT"
echo "bundle: $bundle ($(du -sh "$bundle" | cut -f1), commit $(cat "$bundle/COMMIT"))"
ls "$bundle/bin" "$bundle/lib"
