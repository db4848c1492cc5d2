/* volume_composite.cl — the target upsampled onto the frame and composited over it
 * (docs/volumetric.md §Resolution, upsampling, composite).
 *
 * Variant switches (the host's volume_composite_options()):
 *   VOL_SCALE        resolution divisor s: 1, 2 or 4
 *   VOL_DEPTH_AWARE  1: bilinear x depth similarity; 0: bilinear (the seed's blit)
 *   FOG_PROJECTION, REVERSED_Z  as in volume_march.cl (the pixel's depth for the similarity)
 *   FOG_COLOR_HALF   RGBA half storage; else RGBA float
 *   VOL_LANES        frame pixels per work-item: 16 on CPU devices (volume_composite_cpu.h: PoCL
 *                    vectorises only across work-items, and this kernel's per-pixel branches
 *                    keep it from doing so), 1 elsewhere (coalesced GPU accesses)
 *   FOG_PORTABLE     CPU devices: OpenCL C only, no target builtins (fog_cpu_avx512.h)
 *   VOL_TARGET_RGB   the target holds a coverage per channel (the marched height fog's extinction
 *                    differs per channel: volume_composite.h's layout); one pixel per work-item
 *   FOG_STREAMING_MIN_PIXELS  CPU devices, RGBA32F: frames of at least this many pixels are
 *                    written with non-temporal stores (0: every frame; absent: none)
 * Global size: volume_composite_global() (src/volume/volume_params.h): (ceil(width / VOL_LANES), height),
 * or on CPU devices with VOL_SCALE > 1 (ceil(width / 16), the target row pairs: one work-item
 * takes the VOL_SCALE frame rows between two target rows, volume_composite_cpu.h), rounded up to
 * whole work-groups (src/runtime/work_groups.h): work-items past the frame return.
 */
#pragma OPENCL FP_CONTRACT OFF

#ifndef VOL_LANES
#define VOL_LANES 1
#endif
#if defined(VOL_TARGET_RGB) && VOL_LANES != 1
#error "the per-channel target is composited one pixel per work-item"
#endif
#if VOL_LANES == 16
#define FOG_CLAMP_BY_SELECT /* as in deferred_fog.cl: LLVM keeps IEEE comparisons */
#endif
#define FOG_EXP2 FOG_NAME(fog_exp2_poly)
#include "fog_math.h" /* the one-pixel instance */

#ifdef REVERSED_Z
#define VOL_REVERSED_Z 1
#else
#define VOL_REVERSED_Z 0
#endif
#ifndef VOL_DEPTH_KIND
#define VOL_DEPTH_KIND 0 /* FOG_DEPTH_RAW; 1 (FOG_DEPTH_EYE): linear eye depth, read as it is */
#endif

#include "volume_common.h"
#include "volume_ray.h"
#include "volume_composite.h"

#ifdef FOG_COLOR_HALF
#define COLOR_T half
#else
#define COLOR_T float
#endif

/* One frame pixel: the GPU path and the row tails of the CPU path. */
static inline void vol_composite_pixel(global const COLOR_T* color_in, global const float* depth,
                                       global COLOR_T* color_out, global const float* frame, global const float* low,
                                       global const float* low_key, size_t i, int x, int y) {
  float rho = 0.0f;
#if VOL_DEPTH_AWARE && VOL_SCALE > 1
  rho = vol_inverse_eye_depth(depth[i], frame, FOG_PROJECTION, VOL_REVERSED_Z, VOL_DEPTH_KIND);
#endif
#ifdef VOL_TARGET_RGB
  /* Each channel over its own coverage: color·T_c + P_c, T_c = 1 - A_c (fog.w: the largest A_c). */
  size_t at[4];
  float w[4];
  const int normalise = vol_upsample_weights(x, y, rho, low_key, (int)frame[VOL_F_LOW_WIDTH],
                                             (int)frame[VOL_F_LOW_HEIGHT], VOL_SCALE, VOL_DEPTH_AWARE, at, w);
  const float4 fog = vol_upsample_taps(low, VOL_TARGET_FLOATS(1), 0, at, w, normalise, VOL_SCALE);
  const float4 cover = vol_upsample_taps(low, VOL_TARGET_FLOATS(1), 4, at, w, normalise, VOL_SCALE);
#else
  const float4 fog = vol_upsample(x, y, rho, low, low_key, (int)frame[VOL_F_LOW_WIDTH],
                                  (int)frame[VOL_F_LOW_HEIGHT], VOL_SCALE, VOL_DEPTH_AWARE);
  const float4 cover = fog.wwww;
#endif
#ifdef FOG_COLOR_HALF
  if (fog.w == 0.0f) { /* no fog: the bits pass through (a half trip would quiet a signalling NaN) */
    vstore4(vload4(i, (global const ushort*)color_in), i, (global ushort*)color_out);
    return;
  }
  const float4 c = vload_half4(i, color_in);
#else
  if (fog.w == 0.0f) {
    vstore4(vload4(i, (global const uint*)color_in), i, (global uint*)color_out);
    return;
  }
  const float4 c = vload4(i, color_in);
#endif
  const float4 o = (float4)(vol_composite(c.x, fog.x, cover.x), vol_composite(c.y, fog.y, cover.y),
                            vol_composite(c.z, fog.z, cover.z), c.w);
#ifdef FOG_COLOR_HALF
  vstore_half4_rte(o, i, color_out);
  /* alpha keeps its bits (a half trip would quiet a signalling NaN) */
  ((global ushort*)color_out)[4 * i + 3] = ((global const ushort*)color_in)[4 * i + 3];
#else
  vstore4(o, i, color_out);
#endif
}

#if VOL_LANES == 16
#define FOG_LANES16
#include "fog_math.h" /* the depth formulas lane-wise */
#include "fog_cpu_avx512.h"
#include "volume_composite_cpu.h"
#endif

/* restrict on the read-only inputs lets LLVM hoist frame[] loads past the color stores; not on
 * the colors, which may be one buffer (in place). */
kernel void volume_composite(global const COLOR_T* color_in, global const float* restrict depth, global COLOR_T* color_out,
                             global const float* restrict frame, global const float* restrict low, global const float* restrict low_key) {
  const int width = (int)frame[VOL_F_WIDTH], height = (int)frame[VOL_F_HEIGHT];
#if VOL_LANES == 16
  const int x0 = get_global_id(0) * 16;
  const int stream = FOG_STREAMS(width, height);
#if VOL_SCALE == 1
  const int y = get_global_id(1);
  if (y >= height) return;
  const size_t row = (size_t)y * (size_t)width;
  if (x0 + 16 <= width) {
    vol_composite16(color_in, color_out, low, row + x0, stream);
  } else { /* the row's tail; none for work-items past the row (x0 >= width) */
    for (int x = x0; x < width; ++x) vol_composite_pixel(color_in, depth, color_out, frame, low, low_key, row + x, x, y);
  }
#else
  const int m = get_global_id(1); /* the target row pair: frame rows vol_rows_of(m) */
  int first, last;
  vol_rows_of(m, height, &first, &last);
  if (first >= last) return; /* past the last pair: the global size is rounded up to whole work-groups */
  if (x0 + 16 <= width) {
    vol_composite16(color_in, depth, color_out, frame, low, low_key, x0, m, width, height, stream);
  } else { /* the row's tail; none for work-items past the row (x0 >= width) */
    for (int y = first; y < last; ++y)
      for (int x = x0; x < width; ++x)
        vol_composite_pixel(color_in, depth, color_out, frame, low, low_key, (size_t)y * (size_t)width + x, x, y);
  }
#endif
#elif VOL_LANES == 1
  const int x = get_global_id(0), y = get_global_id(1);
  if (x < width && y < height) vol_composite_pixel(color_in, depth, color_out, frame, low, low_key, (size_t)y * (size_t)width + x, x, y);
#else
#error "VOL_LANES must be 1 or 16"
#endif
}
