/* deferred_fog.cl — the full-screen deferred fog pass (DESIGN.md §2).
 *
 * One work-item per pixel, global size (width, height). Variant switches (set by the host's
 * build_options(); the variant holds no code for a feature the scene does not use):
 *   FOG_MODE       1 linear, 2 linear hard step (start == end), 3 exp, 4 exp2
 *   FOG_DISTANCE   distance-based fog (radial, needs the corner rays and a sqrt); else depth-based
 *   FOG_SKYBOX     fog the skybox too (no sky test); else sky pixels keep f = 1
 *   REVERSED_Z     depth 1 at near, 0 at far (only changes where a NaN depth lands: at the far end)
 *   FOG_COLOR_HALF color stored as RGBA half (vload_half / vstore_half); else RGBA float
 *   FOG_NATIVE_MATH native_exp2 / native_sqrt (the `fast` precision, with -cl-fast-relaxed-math)
 */
#pragma OPENCL FP_CONTRACT OFF /* the same roundings as the scalar path; fma only where written */

#ifdef FOG_NATIVE_MATH
#define exp2 native_exp2
#define sqrt native_sqrt
#endif

#include "fog_math.h"

#ifndef FOG_MODE
#error "FOG_MODE must be defined: 1 linear, 2 linear step, 3 exp, 4 exp2"
#endif
#ifdef REVERSED_Z
#define FOG_REVERSED 1
#else
#define FOG_REVERSED 0
#endif
#ifdef FOG_COLOR_HALF
#define COLOR_T half
#else
#define COLOR_T float4
#endif

/* fog_params: linear (end, 1 / (end - start)); step (start); exp, exp2 (k) — see fog_math.h.
 * corners: far-plane rays, bottom-left, bottom-right, top-left, top-right (xyz used). */
kernel void deferred_fog(global const COLOR_T* color_in, global const float* depth,
                         global COLOR_T* color_out, int width, int height,
                         float4 zbuffer_params, float4 projection_params, float4 corner_bl,
                         float4 corner_br, float4 corner_tl, float4 corner_tr,
                         float4 fog_params, float4 fog_color) {
  const int x = get_global_id(0);
  const int y = get_global_id(1);
  const size_t i = (size_t)y * (size_t)width + (size_t)x;

  const float raw = fog_sanitize_depth(depth[i], FOG_REVERSED);
  const float linear01 = fog_linear01_depth(raw, zbuffer_params.x, zbuffer_params.y);

  float f = 1.0f;
#ifndef FOG_SKYBOX
  if (!fog_is_sky(linear01))
#endif
  {
#ifdef FOG_DISTANCE
    const float u = fog_pixel_u(x, width);
    const float v = fog_pixel_v(y, height);
    const float d = fog_radial_distance(
        linear01, fog_bilerp(corner_bl.x, corner_br.x, corner_tl.x, corner_tr.x, u, v),
        fog_bilerp(corner_bl.y, corner_br.y, corner_tl.y, corner_tr.y, u, v),
        fog_bilerp(corner_bl.z, corner_br.z, corner_tl.z, corner_tr.z, u, v));
#else
    const float d = fog_depth_distance(linear01, projection_params.y, projection_params.z);
#endif
#if FOG_MODE == 1
    f = fog_factor_linear(d, fog_params.x, fog_params.y);
#elif FOG_MODE == 2
    f = fog_factor_step(d, fog_params.x);
#elif FOG_MODE == 3
    f = fog_factor_exp(d, fog_params.x);
#elif FOG_MODE == 4
    f = fog_factor_exp2(d, fog_params.x);
#else
#error "unknown FOG_MODE"
#endif
  }

#ifdef FOG_COLOR_HALF
  if (f == 1.0f) {
    /* Copy the bits: a half -> float -> half round trip would quiet a signalling NaN. */
    ((global ushort4*)color_out)[i] = ((global const ushort4*)color_in)[i];
    return;
  }
  const float4 c = vload_half4(i, color_in);
#else
  const float4 c = color_in[i];
#endif
  float4 o;
  o.x = fog_blend(c.x, fog_color.x, f);
  o.y = fog_blend(c.y, fog_color.y, f);
  o.z = fog_blend(c.z, fog_color.z, f);
  o.w = c.w; /* alpha passes through */
#ifdef FOG_COLOR_HALF
  vstore_half4_rte(o, i, color_out);
#else
  color_out[i] = o;
#endif
}
