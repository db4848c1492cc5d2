// The peer a C++ user would write instead of an OpenCL pass: OpenMP threads over rows, `omp simd`
// over pixels, built with -O3 -march=native (bench/CMakeLists.txt). It evaluates the same formulas
// (kernels/fog_math.h through src/pass/formulas.h) so that the comparison is about execution, not
// maths. Kept in bench/: it is a yardstick, not a library backend.
#pragma once

#include "fogcl/camera.h"
#include "fogcl/fog_settings.h"
#include "fogcl/image.h"

namespace fogcl::bench {

// Fogs rgba32f or rgba16f `in` into `out` (same size and format, allocated by the caller) with
// `threads` OpenMP threads. Built twice: with IEEE maths (-O3 -march=native), and with
// -ffast-math added, which lets GCC call glibc's vector exp2 (libmvec) but drops the NaN/Inf rules.
void openmp_simd_fog(const ColorImage& in, const DepthImage& depth, ColorImage& out,
                     const CameraParams& camera, const FogSettings& settings, int threads);
void openmp_simd_fastmath_fog(const ColorImage& in, const DepthImage& depth, ColorImage& out,
                              const CameraParams& camera, const FogSettings& settings, int threads);

}  // namespace fogcl::bench
