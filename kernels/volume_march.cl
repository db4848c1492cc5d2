/* volume_march.cl — the march of the fog volumes into the reduced-resolution target
 * (docs/volumetric.md §The march). One work-item per target pixel; global size (ceil(W / s),
 * ceil(H / s)). The maths is in the shared headers, which the C++ paths compile too.
 *
 * Variant switches (the host's volume_march_options(); none is optional):
 *   VOL_INTEGRATOR   1 stylized, 2 physical, 3 the physical model's textbook Riemann sum (comparison)
 *   VOL_STEPS        march steps per ray
 *   VOL_FEATURES     bit set of VOL_FEATURE_* (noise, detail, fades, shadow map, adaptive steps)
 *   VOL_JITTER       1: per-ray jitter from (pixel, frame index); 0: none
 *   FOG_PROJECTION   0 perspective, 1 reversed-Z infinite far, 2 orthographic
 *   REVERSED_Z       depth 1 at near
 *   VOL_NOISE_IMAGE  the noise is a 3D image read with the sampler's linear filter; else a
 *                    buffer of unorm8 texels filtered by volume_noise.h
 */
#pragma OPENCL FP_CONTRACT OFF

#define FOG_REAL float
#define FOG_INT int
#define FOG_AS_UINT as_uint
#define FOG_TRUNC_INT convert_int
#define FOG_TO_REAL convert_float
#define FOG_AS_REAL as_float
#define FOG_NAME(name) name
#define FOG_EXP2 fog_exp2_poly
#include "fog_math.h"

#ifdef REVERSED_Z
#define VOL_REVERSED_Z 1
#else
#define VOL_REVERSED_Z 0
#endif

#ifdef VOL_NOISE_IMAGE
constant sampler_t vol_noise_sampler = CLK_NORMALIZED_COORDS_TRUE | CLK_ADDRESS_REPEAT | CLK_FILTER_LINEAR;
#define VOL_NOISE_PARAM read_only image3d_t noise
#define VOL_NOISE_SAMPLE(tex, n, uvw) read_imagef((tex), vol_noise_sampler, (float4)((uvw), 0.0f))
#endif

#include "volume_common.h"
#include "volume_ray.h"
#include "volume_noise.h"
#include "volume_integrate.h"

kernel void volume_march(global const float* depth, global const float* frame, global const float* volumes,
                         int count, VOL_NOISE_PARAM, int noise_size, global const float* shadow_map,
                         uint frame_index, global float* low, global float* low_key) {
  const int lx = get_global_id(0), ly = get_global_id(1);
  const int low_width = (int)frame[VOL_F_LOW_WIDTH];
  if (lx >= low_width || ly >= (int)frame[VOL_F_LOW_HEIGHT]) return;
  float key;
  const float4 r = vol_march_pixel(lx, ly, depth, frame, volumes, count, noise, noise_size, shadow_map, frame_index,
                                   VOL_INTEGRATOR, VOL_STEPS, VOL_FEATURES, VOL_JITTER, FOG_PROJECTION,
                                   VOL_REVERSED_Z, &key);
  const size_t i = (size_t)ly * (size_t)low_width + (size_t)lx;
  vstore4(r, i, low);
  low_key[i] = key;
}
