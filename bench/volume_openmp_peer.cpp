#include "volume_openmp_peer.h"

#include <omp.h>

#include "fogcl/volume_pass.h"
#include "volume/volume_formulas.h"
#include "volume/volume_params.h"

namespace fogcl::bench {

std::size_t openmp_simd_march(const ColorImage& in, const DepthImage& depth, const CameraParams& camera,
                              const VolumeScene& scene, const VolumeSettings& settings, int threads,
                              std::vector<float>& low) {
  using namespace volume_formulas;
  const detail::PackedVolumeFrame f =
      detail::pack_volume_frame(in.width(), in.height(), camera, scene, settings, in.format(), nullptr, 0, 0,
                                max_eye_depth(depth, camera));
  const int lw = f.low_width, lh = f.low_height;
  low.assign(4 * std::size_t(lw) * lh, 0.0f);
  if (f.nothing_to_march()) return std::size_t(lw) * lh;
  const detail::VolumeVariant& v = f.variant;
  const std::uint8_t* noise = f.needs_noise()
                                  ? detail::shared_noise_texture(settings.noise_size, settings.noise_seed).texels.data()
                                  : nullptr;
  const int integrator = v.integrator == VolumeIntegrator::stylized ? VOL_STYLIZED : VOL_PHYSICAL;
  const int count = int(f.visible.size()), projection = int(v.projection), reversed = v.reversed_z;
  const float* d = depth.data();
  const float* frame = f.frame.data();
  const float* vols = f.volumes.data();
  float* out = low.data();
  // Rows differ in cost (sky, volumes): dynamic scheduling, as PoCL's work-groups are.
#pragma omp parallel for schedule(dynamic) num_threads(threads)
  for (int ly = 0; ly < lh; ++ly) {
#pragma omp simd
    for (int lx = 0; lx < lw; ++lx) {
      float key, coverage[3];
      const glm::vec4 p = vol_march_pixel<float>(lx, ly, d, frame, vols, count, noise, settings.noise_size, nullptr,
                                                 scene.frame_index, integrator, v.steps, v.features, v.height_features, v.jitter,
                                                 projection, reversed, int(v.depth_kind), &key, coverage);
      float* o = out + 4 * (std::size_t(ly) * lw + lx);
      o[0] = p.x;
      o[1] = p.y;
      o[2] = p.z;
      o[3] = p.w;
    }
  }
  return std::size_t(lw) * lh;
}

}  // namespace fogcl::bench
