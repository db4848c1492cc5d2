// The scalar C++ path of the volumetric pass: one thread, the shared kernel headers
// (kernels/volume_*.h) instantiated in T. float is the baseline and the fallback without OpenCL;
// double is the reference every other path is measured against (docs/volumetric.md §Error).
#pragma once

#include <vector>

#include "fogcl/camera.h"
#include "fogcl/image.h"
#include "fogcl/volumes.h"

namespace fogcl {

template <class T>
struct VolumeResult {
  int width = 0, height = 0;          // the frame
  std::vector<T> rgba;                // 4 * width * height: the composited frame, in T
  std::vector<T> coverage;            // width * height: the upsampled coverage A (0: untouched)
  int low_width = 0, low_height = 0;  // the target: ceil(W / s) x ceil(H / s)
  int low_floats = 4;                 // per target pixel: 4, or 8 with a coverage per channel
  std::vector<T> low;                 // low_floats per target pixel: premultiplied RGB, coverage A, and
                                      // where the marched height fog's extinction differs per channel
                                      // the coverage per channel (A_r, A_g, A_b, 0), A their largest
  std::vector<T> low_key;             // per target pixel: the eye depth it marched to (+inf sky)
  std::size_t visible = 0;            // volumes left after culling
};

// The whole pass in T: culling (with the depth image's range), the march at the settings'
// resolution, the upsampling and the composite. Nothing visible: rgba is the input.
template <class T>
VolumeResult<T> volumes_scalar(const ConstColorView& in, const ConstDepthView& depth, const CameraParams& camera,
                               const VolumeScene& scene, const VolumeSettings& settings,
                               const ShadowMap* shadow = nullptr);

// Fogs `in` into `out` in float, in in's storage format (out may be in), with the OpenCL pass's
// rules: A == 0 pixels keep their bits, alpha passes through.
void apply_volumes_scalar(const ColorImage& in, const DepthImage& depth, ColorImage& out,
                          const CameraParams& camera, const VolumeScene& scene, const VolumeSettings& settings,
                          const ShadowMap* shadow = nullptr);
// The same over the caller's memory (views, image.h; any row stride): out must have in's size and
// format and be in itself or memory apart from in and depth.
void apply_volumes_scalar(const ConstColorView& in, const ConstDepthView& depth, const ColorView& out,
                          const CameraParams& camera, const VolumeScene& scene, const VolumeSettings& settings,
                          const ShadowMap* shadow = nullptr);

// max over pixels and R, G, B of |image - reference.rgba| (NaN differences count as +inf).
double max_abs_rgb_error(const ConstColorView& image, const VolumeResult<double>& reference);

extern template VolumeResult<float> volumes_scalar<float>(const ConstColorView&, const ConstDepthView&,
                                                          const CameraParams&, const VolumeScene&,
                                                          const VolumeSettings&, const ShadowMap*);
extern template VolumeResult<double> volumes_scalar<double>(const ConstColorView&, const ConstDepthView&,
                                                            const CameraParams&, const VolumeScene&,
                                                            const VolumeSettings&, const ShadowMap*);

}  // namespace fogcl
