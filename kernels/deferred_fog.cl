/* deferred_fog.cl — the full-screen deferred fog pass (docs/DESIGN.md §2).
 *
 * Variant switches, set by the host's build_options(); a variant holds no code for a feature the
 * scene does not use:
 *   FOG_MODE          1 linear, 2 linear hard step (start == end), 3 exp, 4 exp2, 5 height
 *                     (docs/DESIGN.md §6: along the ray, from the camera pose; 16-pixel blocks
 *                     on CPU devices as the other modes, fog_height_pixels16)
 *   FOG_HEIGHT_FALLOFF, _RGB, _START, _CUTOFF, _MAX_OPACITY, _SUN, _SUN_START, _SAME_IN  height
 *                     fog's parts (fog_math.h FOG_HF_*): falloff k != 0, per-channel coefficients,
 *                     start > 0, a finite cut-off, maximum opacity < 1, the sun lobe, its own
 *                     start, in-scattering equal to extinction (T and J from one exponential)
 *   FOG_DISTANCE      distance-based fog (corner interpolation, and a sqrt but for exp2); else
 *                     depth-based
 *   FOG_SKYBOX        fog the skybox too (no sky test); else sky pixels keep f = 1
 *   FOG_DEPTH_KIND    what the depth buffer holds: 0 raw device depth (default), 1 linear eye
 *                     depth, 2 radial distance (fog_view_distance_linear: never through raw depth;
 *                     the corners are then the rays at view z = 1)
 *   FOG_SKY_INFINITE  the sky is infinitely far: fully fogged in every mode (with FOG_SKYBOX)
 *   REVERSED_Z        depth 1 at near, 0 at far (decides where a NaN depth lands: the far end)
 *   FOG_PROJECTION    0 perspective (default), 1 reversed-Z infinite far, 2 orthographic
 *   FOG_COLOR_HALF    color stored as RGBA half; else RGBA float
 *   FOG_NATIVE_MATH   native_sqrt, and native_exp2 on GPUs (the `fast` precision, with
 *                     -cl-fast-relaxed-math)
 *   FOG_VECTOR_WIDTH  pixels per work-item: 16 on CPU devices, 1 elsewhere.
 *   FOG_STREAMING_MIN_PIXELS  CPU devices, RGBA32F: frames of at least this many pixels are
 *                     written with non-temporal stores (0: every frame; absent: none)
 *   FOG_PORTABLE      CPU devices: OpenCL C only, no target builtins (fog_cpu_avx512.h)
 *
 * Why 16 pixels per work-item on CPUs: PoCL vectorises only across work-items, and a library
 * exp2 blocks that. Explicit float16 arithmetic maps straight onto SIMD registers, one lane per
 * pixel; colors are processed as 4 pixels x RGBA per float16 with the fog factor broadcast to its
 * pixel's channels. The pass is then bound by instruction throughput, not memory, so each block
 * of 16 pixels takes the cheapest of four blends (fog_cpu_blocks.h). GPUs keep one pixel per
 * work-item, which keeps their memory accesses coalesced.
 * Global size: (ceil(width / FOG_VECTOR_WIDTH), height).
 */
#pragma OPENCL FP_CONTRACT OFF /* round like the scalar path: fma only where written */

#ifndef FOG_MODE
#error "FOG_MODE must be defined: 1 linear, 2 linear step, 3 exp, 4 exp2, 5 height"
#endif
#ifndef FOG_VECTOR_WIDTH
#define FOG_VECTOR_WIDTH 1
#endif
#ifdef FOG_NATIVE_MATH
#undef sqrt /* PoCL's headers define it as a macro under -cl-fast-relaxed-math */
#define sqrt native_sqrt
#if FOG_VECTOR_WIDTH == 1
/* The contract of fog_exp2_poly: 2^min(x, 0). CPU devices keep the polynomial: it is faster than
 * PoCL's native_exp2 (1080p exp2 fog 1.06 vs 1.24 ms) and accurate. */
#define FOG_EXP2(x) native_exp2(fmin((x), 0.0f))
#endif
#endif
#ifdef FOG_DISTANCE
#define FOG_USE_DISTANCE 1
#else
#define FOG_USE_DISTANCE 0
#endif
#ifdef FOG_SKYBOX
#define FOG_USE_SKYBOX 1
#else
#define FOG_USE_SKYBOX 0
#endif
#ifndef FOG_PROJECTION
#define FOG_PROJECTION 0
#endif
#ifndef FOG_DEPTH_KIND
#define FOG_DEPTH_KIND 0
#endif
#ifdef FOG_SKY_INFINITE
#define FOG_USE_SKY_INFINITE 1
#else
#define FOG_USE_SKY_INFINITE 0
#endif
#ifdef REVERSED_Z
#define FOG_USE_REVERSED_Z 1
#else
#define FOG_USE_REVERSED_Z 0
#endif

#ifndef FOG_EXP2
#define FOG_EXP2 FOG_NAME(fog_exp2_poly)
#endif
#if FOG_MODE == 5
/* Height fog's parts as fog_math.h's FOG_HF_* bit mask, a compile-time constant (the names
 * expand where used, after the include). */
#ifdef FOG_HEIGHT_FALLOFF
#define FOG_HB_FALLOFF FOG_HF_FALLOFF
#else
#define FOG_HB_FALLOFF 0
#endif
#ifdef FOG_HEIGHT_RGB
#define FOG_HB_RGB FOG_HF_RGB
#else
#define FOG_HB_RGB 0
#endif
#ifdef FOG_HEIGHT_START
#define FOG_HB_START FOG_HF_START
#else
#define FOG_HB_START 0
#endif
#ifdef FOG_HEIGHT_CUTOFF
#define FOG_HB_CUTOFF FOG_HF_CUTOFF
#else
#define FOG_HB_CUTOFF 0
#endif
#ifdef FOG_HEIGHT_MAX_OPACITY
#define FOG_HB_MAX_OPACITY FOG_HF_MAX_OPACITY
#else
#define FOG_HB_MAX_OPACITY 0
#endif
#ifdef FOG_HEIGHT_SUN
#define FOG_HB_SUN FOG_HF_SUN
#else
#define FOG_HB_SUN 0
#endif
#ifdef FOG_HEIGHT_SUN_START
#define FOG_HB_SUN_START FOG_HF_SUN_START
#else
#define FOG_HB_SUN_START 0
#endif
#ifdef FOG_HEIGHT_SAME_IN
#define FOG_HB_SAME_IN FOG_HF_SAME_IN
#else
#define FOG_HB_SAME_IN 0
#endif
#define FOG_HEIGHT_BITS (FOG_HB_FALLOFF | FOG_HB_RGB | FOG_HB_START | FOG_HB_CUTOFF | FOG_HB_MAX_OPACITY | \
                         FOG_HB_SUN | FOG_HB_SUN_START | FOG_HB_SAME_IN | (FOG_USE_SKYBOX ? FOG_HF_SKYBOX : 0))
#endif
#if FOG_VECTOR_WIDTH == 1
#define FOG_DEVICE_EXP /* GPUs: height fog's e^x from the device (fog_math.h) */
#endif
#if FOG_VECTOR_WIDTH == 16
#define FOG_CLAMP_BY_SELECT /* CPU devices: LLVM keeps IEEE comparisons (fog_sanitize_depth) */
#endif
/* Whether the pixel's ray is read, and whether its term is |ray|^2 (fog_math.h, FOG_RAY_SQUARED). */
#define FOG_USE_RAY FOG_NEEDS_RAY(FOG_USE_DISTANCE, FOG_DEPTH_KIND)
#define FOG_USE_SQUARED FOG_RAY_SQUARED(FOG_MODE, FOG_USE_DISTANCE, FOG_DEPTH_KIND)

#include "fog_math.h" /* the one-pixel instance */

#if FOG_VECTOR_WIDTH == 16
#include "fog_cpu_avx512.h"
#endif
#define FOG_LANES16
#ifdef FOG_AVX512
#define FOG_CEIL fog_ceil_avx512
#define FOG_FLOOR fog_floor_avx512
#define FOG_SCALE2 fog_scale2_avx512
#define FOG_EXP2_LDEXP fog_exp2_ldexp_avx512
#endif
#include "fog_math.h" /* the 16-pixel instance */

#ifdef FOG_COLOR_HALF
#define COLOR_T half
#else
#define COLOR_T float
#endif

/* Per-frame constants, unpacked once per work-item. */
typedef struct {
  float zx, zy, near_plane, far_plane, k_a, k_b;
  float4 fog_color, bl, br, tl, tr;
  float inv_width, height;
  int stream; /* CPU path: this frame's blocks use non-temporal stores (FOG_STREAMS) */
#if FOG_MODE == FOG_MODE_HEIGHT
  float hp[FOG_HP_COUNT]; /* fog_math.h's FOG_HP_* block */
  float d0;               /* eye.y - base height */
  float4 up, light;       /* world +y and the light, in view space */
#endif
} FogConstants;

/* One pixel (index i in the frame; color RGBA at 4 * i) as one vector load and store: GPUs, and
 * CPU devices' row tails. GPUs read and write it through its aligned vector type (a buffer starts
 * on CL_DEVICE_MEM_BASE_ADDR_ALIGN, at least 16 bytes), one memory instruction where vload4's
 * element alignment gave NVIDIA four; CPU devices keep vload4: their buffers may be the caller's
 * host memory, aligned to the element only. T: the element type. */
#if FOG_VECTOR_WIDTH == 1
#define FOG_LOAD4(T, p, i) (((global const T##4*)(p))[i])
#define FOG_STORE4(T, v, p, i) (((global T##4*)(p))[i] = (v))
#else
#define FOG_LOAD4(T, p, i) vload4((i), (global const T*)(p))
#define FOG_STORE4(T, v, p, i) vstore4((v), (i), (global T*)(p))
#endif
static inline float4 fog_load_pixel(global const COLOR_T* color, size_t i) {
#ifdef FOG_COLOR_HALF
  const ushort4 bits = FOG_LOAD4(ushort, color, i);
  return vload_half4(0, (const half*)&bits);
#else
  return FOG_LOAD4(float, color, i);
#endif
}
static inline void fog_store_pixel(float4 o, global COLOR_T* color, size_t i) {
#ifdef FOG_COLOR_HALF
  ushort4 bits;
  vstore_half4_rte(o, 0, (half*)&bits);
  FOG_STORE4(ushort, bits, color, i);
#else
  FOG_STORE4(float, o, color, i);
#endif
}
/* The pixel's bits unchanged: in half storage a half -> float -> half trip would quiet a
 * signalling NaN. */
static inline void fog_copy_pixel(global const COLOR_T* color_in, global COLOR_T* color_out, size_t i) {
#ifdef FOG_COLOR_HALF
  FOG_STORE4(ushort, FOG_LOAD4(ushort, color_in, i), color_out, i);
#else
  FOG_STORE4(uint, FOG_LOAD4(uint, color_in, i), color_out, i);
#endif
}

/* Blends one pixel with its fog factor f. */
static inline void fog_blend_pixel(global const COLOR_T* color_in, global COLOR_T* color_out,
                                   size_t i, float f, const FogConstants* k) {
#ifdef FOG_COLOR_HALF
  if (f == 1.0f) {
    fog_copy_pixel(color_in, color_out, i);
    return;
  }
#endif
  const float4 c = fog_load_pixel(color_in, i);
  const float4 o = (float4)(fog_blend(c.x, k->fog_color.x, f), fog_blend(c.y, k->fog_color.y, f),
                            fog_blend(c.z, k->fog_color.z, f), c.w /* alpha passes through */);
  fog_store_pixel(o, color_out, i);
}

#if FOG_MODE == FOG_MODE_HEIGHT
/* One pixel of height fog (docs/DESIGN.md §6) at column x, row y. */
static inline void fog_pixel(global const COLOR_T* color_in, global const float* depth,
                             global COLOR_T* color_out, size_t i, int x, int y,
                             const FogConstants* k) {
  const float u = fog_pixel_u((float)x, k->inv_width), v = fog_pixel_v((float)y, k->height);
  int sky;
  float wy, d0, q_sun;
  const float s_hit = fog_height_geometry(
      depth[i], fog_bilerp(k->bl.x, k->br.x, k->tl.x, k->tr.x, u, v), fog_bilerp(k->bl.y, k->br.y, k->tl.y, k->tr.y, u, v),
      fog_bilerp(k->bl.z, k->br.z, k->tl.z, k->tr.z, u, v), FOG_DEPTH_KIND, FOG_USE_REVERSED_Z, FOG_PROJECTION, k->zx,
      k->zy, k->near_plane, k->far_plane, k->up.x, k->up.y, k->up.z, k->light.x, k->light.y, k->light.z,
      FOG_HB_SUN != 0, k->d0, &sky, &wy, &d0, &q_sun);
  const float4 c = fog_load_pixel(color_in, i);
  float rgb[3] = {c.x, c.y, c.z};
  if (!fog_height_pixel(rgb, s_hit, sky, wy, d0, q_sun, k->hp, FOG_HEIGHT_BITS)) {
    fog_copy_pixel(color_in, color_out, i);
    return;
  }
  fog_store_pixel((float4)(rgb[0], rgb[1], rgb[2], c.w /* alpha passes through */), color_out, i);
}
#else
/* One pixel at column x, row y: the GPU path and the row tails of the CPU path. */
static inline void fog_pixel(global const COLOR_T* color_in, global const float* depth,
                             global COLOR_T* color_out, size_t i, int x, int y,
                             const FogConstants* k) {
  float ray = 0.0f;
#if FOG_USE_RAY
  const float u = fog_pixel_u((float)x, k->inv_width), v = fog_pixel_v((float)y, k->height);
  ray = fog_ray_term(fog_bilerp(k->bl.x, k->br.x, k->tl.x, k->tr.x, u, v),
                     fog_bilerp(k->bl.y, k->br.y, k->tl.y, k->tr.y, u, v),
                     fog_bilerp(k->bl.z, k->br.z, k->tl.z, k->tr.z, u, v), FOG_USE_SQUARED);
#endif
  const float f = fog_factor(depth[i], ray, FOG_DEPTH_KIND, FOG_MODE, FOG_USE_DISTANCE, FOG_USE_SKYBOX,
                             FOG_USE_SKY_INFINITE, FOG_USE_REVERSED_Z, FOG_PROJECTION, k->zx, k->zy, k->near_plane, k->far_plane,
                             k->k_a, k->k_b);
  fog_blend_pixel(color_in, color_out, i, f, k);
}
#endif

#if FOG_VECTOR_WIDTH == 16
#include "fog_cpu_blocks.h"
#endif

#if FOG_VECTOR_WIDTH == 16 && FOG_MODE == FOG_MODE_HEIGHT
/* Height fog on 16 pixels of a row (CPU devices): the same formulas on float16 lanes, one pixel a
 * lane. The four RGBA quads are split into R, G, B vectors and put back together by two-source
 * permutes (FOG_SHUFFLE), 14 for the block: written as vector swizzles, LLVM assembled the same
 * split from 32 eight-byte loads and some 70 inserts and permutes. Pixels that pass through keep
 * their bits (a select in float storage; copied back in half storage). */
static inline void fog_height_pixels16(global const COLOR_T* color_in, global const float* depth,
                                       global COLOR_T* color_out, size_t i0, int x0, int y,
                                       const FogConstants* k) {
  const float16 lane = (float16)(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
  const float16 u = fog_pixel_u_v((float16)((float)x0) + lane, (float16)k->inv_width);
  const float16 v = (float16)fog_pixel_v((float)y, k->height);
  int16 sky;
  float16 wy, d0, q_sun;
  const float16 s_hit = fog_height_geometry_v(
      vload16(0, depth + i0), fog_bilerp_v((float16)k->bl.x, (float16)k->br.x, (float16)k->tl.x, (float16)k->tr.x, u, v),
      fog_bilerp_v((float16)k->bl.y, (float16)k->br.y, (float16)k->tl.y, (float16)k->tr.y, u, v),
      fog_bilerp_v((float16)k->bl.z, (float16)k->br.z, (float16)k->tl.z, (float16)k->tr.z, u, v), FOG_DEPTH_KIND,
      FOG_USE_REVERSED_Z, FOG_PROJECTION, (float16)k->zx, (float16)k->zy, (float16)k->near_plane,
      (float16)k->far_plane, (float16)k->up.x, (float16)k->up.y, (float16)k->up.z, (float16)k->light.x,
      (float16)k->light.y, (float16)k->light.z, FOG_HB_SUN != 0, (float16)k->d0, &sky, &wy, &d0, &q_sun);
  global const COLOR_T* in = color_in + 4 * i0;
  global COLOR_T* out = color_out + 4 * i0;
  const float16 q0 = fog_load_quad(in, 0), q1 = fog_load_quad(in, 1), q2 = fog_load_quad(in, 2),
                q3 = fog_load_quad(in, 3);
  /* Pixels 0-7 (from q0, q1) and 8-15 (q2, q3): R in lanes 0-7, G in 8-15; B in 0-7, A in 8-15. */
#define FOG_H_SPLIT(a, b, c0, c1)                                                                  \
  FOG_SHUFFLE(a, b, c0, c0 + 4, c0 + 8, c0 + 12, c0 + 16, c0 + 20, c0 + 24, c0 + 28, c1, c1 + 4, c1 + 8, \
              c1 + 12, c1 + 16, c1 + 20, c1 + 24, c1 + 28)
  const float16 rg_lo = FOG_H_SPLIT(q0, q1, 0, 1), ba_lo = FOG_H_SPLIT(q0, q1, 2, 3);
  const float16 rg_hi = FOG_H_SPLIT(q2, q3, 0, 1), ba_hi = FOG_H_SPLIT(q2, q3, 2, 3);
#undef FOG_H_SPLIT
  float16 rgb[3] = {FOG_SHUFFLE(rg_lo, rg_hi, 0, 1, 2, 3, 4, 5, 6, 7, 16, 17, 18, 19, 20, 21, 22, 23),
                    FOG_SHUFFLE(rg_lo, rg_hi, 8, 9, 10, 11, 12, 13, 14, 15, 24, 25, 26, 27, 28, 29, 30, 31),
                    FOG_SHUFFLE(ba_lo, ba_hi, 0, 1, 2, 3, 4, 5, 6, 7, 16, 17, 18, 19, 20, 21, 22, 23)};
  const int16 fogged = fog_height_pixel_v(rgb, s_hit, sky, wy, d0, q_sun, k->hp, FOG_HEIGHT_BITS);
  /* Lanes passed through: bit j set where pixel j is not fogged. */
  const uint keep = fog_lanes_equal(as_float16(fogged & as_int16((float16)1.0f)), 0.0f);
  global const uint* in_bits = (global const uint*)in;
  global uint* out_bits = (global uint*)out;
  if (keep == 0xffffu) {
    fog_copy_block(in_bits, out_bits, k);
    return;
  }
  /* Back to quads: R and G of pixels 0-7 interleaved (rg0), B and A (ba0), then pixels 8-15; the
   * alpha lanes are the input's. */
  const float16 rg0 = FOG_SHUFFLE(rgb[0], rgb[1], 0, 16, 1, 17, 2, 18, 3, 19, 4, 20, 5, 21, 6, 22, 7, 23);
  const float16 rg1 = FOG_SHUFFLE(rgb[0], rgb[1], 8, 24, 9, 25, 10, 26, 11, 27, 12, 28, 13, 29, 14, 30, 15, 31);
  const float16 ba0 = FOG_SHUFFLE(rgb[2], ba_lo, 0, 24, 1, 25, 2, 26, 3, 27, 4, 28, 5, 29, 6, 30, 7, 31);
  const float16 ba1 = FOG_SHUFFLE(rgb[2], ba_hi, 8, 24, 9, 25, 10, 26, 11, 27, 12, 28, 13, 29, 14, 30, 15, 31);
#define FOG_H_MERGE(rg, ba, p)                                                                     \
  FOG_SHUFFLE(rg, ba, p, p + 1, p + 16, p + 17, p + 2, p + 3, p + 18, p + 19, p + 4, p + 5, p + 20, \
              p + 21, p + 6, p + 7, p + 22, p + 23)
  fog_store_quad(FOG_H_MERGE(rg0, ba0, 0), out, 0, k);
  fog_store_quad(FOG_H_MERGE(rg0, ba0, 8), out, 1, k);
  fog_store_quad(FOG_H_MERGE(rg1, ba1, 0), out, 2, k);
  fog_store_quad(FOG_H_MERGE(rg1, ba1, 8), out, 3, k);
#undef FOG_H_MERGE
#ifdef FOG_COLOR_HALF
  if (keep != 0) fog_restore_kept(keep, in_bits, out_bits);
#endif
}
#define fog_pixels16 fog_height_pixels16
#endif

#if FOG_MODE == FOG_MODE_HEIGHT
/* A float4's x, y, z into three entries of the FOG_HP_* block. */
static inline void fog_put_rgb(float* p, float4 v) {
  p[0] = v.x;
  p[1] = v.y;
  p[2] = v.z;
}
#endif

kernel void deferred_fog(global const COLOR_T* color_in, global const float* depth,
                         global COLOR_T* color_out, int width, int height,
                         float4 zbuffer_params, float4 projection_params, float4 corner_bl,
                         float4 corner_br, float4 corner_tl, float4 corner_tr,
                         float4 fog_params, float4 fog_color
#if FOG_MODE == FOG_MODE_HEIGHT
                         , float4 height_a /* k, start, cut-off, m */, float4 height_b /* 1 - m, e, s_sun, d0 */,
                         float4 extinction, float4 inscattering, float4 sun_color, float4 up_view,
                         float4 light_view
#endif
                         ) {
  FogConstants k;
  k.zx = zbuffer_params.x;
  k.zy = zbuffer_params.y;
  k.near_plane = projection_params.y;
  k.far_plane = projection_params.z;
  k.k_a = fog_params.x;
  k.k_b = fog_params.y;
  k.fog_color = fog_color;
  k.bl = corner_bl;
  k.br = corner_br;
  k.tl = corner_tl;
  k.tr = corner_tr;
  k.inv_width = 1.0f / (float)width;
  k.height = (float)height;
#if FOG_MODE == FOG_MODE_HEIGHT
  k.hp[FOG_HP_K] = height_a.x;
  k.hp[FOG_HP_START] = height_a.y;
  k.hp[FOG_HP_CUTOFF] = height_a.z;
  k.hp[FOG_HP_MAX] = height_a.w;
  k.hp[FOG_HP_MIN_T] = height_b.x;
  k.hp[FOG_HP_SUN_EXP] = height_b.y;
  k.hp[FOG_HP_SUN_START] = height_b.z;
  k.d0 = height_b.w;
  fog_put_rgb(k.hp + FOG_HP_EXT, extinction);
  fog_put_rgb(k.hp + FOG_HP_IN, inscattering);
  fog_put_rgb(k.hp + FOG_HP_FOG, fog_color);
  fog_put_rgb(k.hp + FOG_HP_SUN, sun_color);
  k.up = up_view;
  k.light = light_view;
#endif
#if FOG_VECTOR_WIDTH == 16
  k.stream = FOG_STREAMS(width, height);
#endif
  const int y = get_global_id(1);
  const size_t row = (size_t)y * (size_t)width;
#if FOG_VECTOR_WIDTH == 16
  const int x0 = get_global_id(0) * 16;
  if (x0 + 16 <= width) {
    fog_pixels16(color_in, depth, color_out, row + x0, x0, y, &k);
  } else {
    for (int x = x0; x < width; ++x) fog_pixel(color_in, depth, color_out, row + x, x, y, &k);
  }
#elif FOG_VECTOR_WIDTH == 1
  const int x = get_global_id(0);
  fog_pixel(color_in, depth, color_out, row + x, x, y, &k);
#else
#error "FOG_VECTOR_WIDTH must be 1 or 16"
#endif
}
