// The peer a C++ user would write for the volumetric march instead of an OpenCL kernel: the same
// per-pixel march (kernels/volume_integrate.h through src/volume/volume_formulas.h, so the
// comparison is about execution, not maths), OpenMP threads over target rows and `omp simd` over
// their pixels, built -O3 -march=native (bench/CMakeLists.txt). A yardstick kept in bench/.
#pragma once

#include <vector>

#include "fogcl/camera.h"
#include "fogcl/image.h"
#include "fogcl/volumes.h"

namespace fogcl::bench {

// Marches the target of (scene, settings) for the frame (in, depth) with `threads` OpenMP threads:
// premultiplied RGB + coverage per target pixel into `low` (resized), row-major. Returns the
// number of target pixels.
std::size_t openmp_simd_march(const ColorImage& in, const DepthImage& depth, const CameraParams& camera,
                              const VolumeScene& scene, const VolumeSettings& settings, int threads,
                              std::vector<float>& low);

}  // namespace fogcl::bench
