// The peer an image-pipeline engineer would write instead of an OpenCL pass: the deferred fog pass
// in Halide 14, JIT-compiled for the host (bench/halide_peer.cpp). Parallel over bands of 4 rows,
// vectorised by 16 pixels over x (the fastest schedule found: halide_peer.cpp's end), interleaved
// RGBA32F or RGBA16F in and out, the sky test and the formulas of
// kernels/fog_math.h written again as Halide expressions (a separate implementation, like
// bench/openmp_peer.cpp; its error against the float64 path is measured in the bench). Built only
// when CMake finds Halide (bench/CMakeLists.txt; `scripts/setup.sh --bench` installs it).
#pragma once

#include <cstddef>

#include "fogcl/camera.h"
#include "fogcl/fog_settings.h"
#include "fogcl/image.h"

namespace fogcl::bench {

// JIT-compiles (once per variant and storage; later calls find it) the pipeline of the variant
// `settings` and `camera` select for `storage`, so that the timed calls do not compile. `threads`:
// the size of Halide's thread pool (HL_NUM_THREADS); it is read once, before the first pipeline runs.
using HalidePrepare = void(const CameraParams& camera, const FogSettings& settings, ColorFormat storage, int threads);

// Fogs `in` into `out` (same size and format, allocated by the caller): one realize() of the
// prepared pipeline (prepares it first if needed) on the images' own memory.
using HalideFog = void(const ColorImage& in, const DepthImage& depth, ColorImage& out, const CameraParams& camera,
                       const FogSettings& settings, int threads);

// Copies rows x row_bytes (a multiple of 4) from src to dst with a Halide pipeline (32-bit words,
// 64 a step, rows in parallel when threads > 1): the Halide entry of the bench's copy ceiling.
using HalideCopy = void(const void* src, void* dst, std::size_t row_bytes, int rows, int threads);

}  // namespace fogcl::bench

// The module's entry points (bench/CMakeLists.txt builds it as a module that fog_bench.cpp loads
// with dlopen: Halide's LLVM 14 must stay out of the global scope of a process that runs PoCL's
// LLVM 15).
extern "C" fogcl::bench::HalidePrepare fogcl_halide_prepare;
extern "C" fogcl::bench::HalideFog fogcl_halide_fog;
extern "C" fogcl::bench::HalideCopy fogcl_halide_copy;
