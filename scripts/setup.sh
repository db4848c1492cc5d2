#!/usr/bin/env bash
# Installs the Debian packages fogcl needs, only those missing. Runs as root or through sudo.
set -euo pipefail
packages=(
  cmake g++ make
  pocl-opencl-icd ocl-icd-opencl-dev opencl-c-headers opencl-clhpp-headers
  libglm-dev libimath-dev libopenexr-dev libpng-dev libcli11-dev nlohmann-json3-dev pkg-config
  libgtest-dev libbenchmark-dev
  libvulkan-dev  # examples/vulkan_exporter.cpp and the Vulkan rows of the interop bench
  python3-matplotlib
  pybind11-dev python3-pybind11 python3-numpy python3-pytest python3-pyopencl
)
# --sanitizers: also clang and its runtimes (libFuzzer, ASan, UBSan) for `make asan-test` / `make fuzz`.
if [ "${1:-}" = "--sanitizers" ]; then
  packages+=(clang-14 libclang-rt-14-dev)
fi
# --bench: also Halide 14 for the Halide peer (bench/halide_peer.cpp; the bench builds it only when
# Halide is found). matplotlib, which bench/plot.py and the report plots draw with, is in the base
# set: the report tests draw and check the plots.
if [ "${1:-}" = "--bench" ]; then
  packages+=(libhalide14-0-dev)
fi
# --renderers: also Blender (Cycles), which the renderer tests render with (tests/blender; the
# BlenderCamera tests of fogcl_tests skip where it is missing, and fail with FOGCL_BLENDER_TEST=required).
if [ "${1:-}" = "--renderers" ]; then
  packages+=(blender)
fi
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0
echo "setup: installing ${missing[*]}"
sudo=""
[ "$(id -u)" -eq 0 ] || sudo="sudo"
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
