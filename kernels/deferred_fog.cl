/* deferred_fog.cl — the full-screen deferred fog pass (DESIGN.md §2).
 *
 * Variant switches, set by the host's build_options(); a variant holds no code for a feature the
 * scene does not use:
 *   FOG_MODE          1 linear, 2 linear hard step (start == end), 3 exp, 4 exp2
 *   FOG_DISTANCE      distance-based fog (corner interpolation and a sqrt); else depth-based
 *   FOG_SKYBOX        fog the skybox too (no sky test); else sky pixels keep f = 1
 *   REVERSED_Z        depth 1 at near, 0 at far (decides where a NaN depth lands: the far end)
 *   FOG_PROJECTION    0 perspective (default), 1 reversed-Z infinite far, 2 orthographic
 *   FOG_COLOR_HALF    color stored as RGBA half; else RGBA float
 *   FOG_NATIVE_MATH   native_sqrt, and native_exp2 on GPUs (the `fast` precision, with
 *                     -cl-fast-relaxed-math)
 *   FOG_VECTOR_WIDTH  pixels per work-item: 16 on CPU devices, 1 elsewhere.
 *   FOG_STREAMING_STORES  non-temporal stores of RGBA32F blocks (CPU devices)
 *   FOG_PORTABLE      CPU devices: OpenCL C only, no target builtins (see fog_pixels16)
 *
 * Why 16 pixels per work-item on CPUs: PoCL vectorises only across work-items, and a library
 * exp2 blocks that. Explicit float16 arithmetic maps straight onto SIMD registers, one lane per
 * pixel; colors are processed as 4 pixels x RGBA per float16 with the fog factor broadcast to its
 * pixel's channels. The pass is then bound by instruction throughput, not memory, so each block
 * of 16 pixels takes the cheapest of four blends (fog_pixels16). GPUs keep one pixel per
 * work-item, which keeps their memory accesses coalesced.
 * Global size: (ceil(width / FOG_VECTOR_WIDTH), height).
 */
#pragma OPENCL FP_CONTRACT OFF /* round like the scalar path: fma only where written */

#ifndef FOG_MODE
#error "FOG_MODE must be defined: 1 linear, 2 linear step, 3 exp, 4 exp2"
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
#ifdef REVERSED_Z
#define FOG_USE_REVERSED_Z 1
#else
#define FOG_USE_REVERSED_Z 0
#endif

#ifndef FOG_EXP2
#define FOG_EXP2 FOG_NAME(fog_exp2_poly)
#endif

#define FOG_REAL float
#define FOG_INT int
#define FOG_AS_UINT as_uint
#define FOG_TRUNC_INT convert_int
#define FOG_TO_REAL convert_float
#define FOG_AS_REAL as_float
#define FOG_NAME(name) name
#include "fog_math.h" /* undefines the instance macros above */

#define FOG_REAL float16
#define FOG_INT int16
#define FOG_AS_UINT as_uint16
#define FOG_TRUNC_INT convert_int16
#define FOG_TO_REAL convert_float16
#define FOG_AS_REAL as_float16
#define FOG_NAME(name) name##_v
#include "fog_math.h" /* undefines the instance macros above */

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
} FogConstants;

/* Blends one pixel (index i in the frame; color RGBA at 4 * i) with its fog factor f. */
static inline void fog_blend_pixel(global const COLOR_T* color_in, global COLOR_T* color_out,
                                   size_t i, float f, const FogConstants* k) {
#ifdef FOG_COLOR_HALF
  if (f == 1.0f) {
    /* Copy the bits: a half -> float -> half trip would quiet a signalling NaN. */
    vstore4(vload4(i, (global const ushort*)color_in), i, (global ushort*)color_out);
    return;
  }
  const float4 c = vload_half4(i, color_in);
#else
  const float4 c = vload4(i, color_in);
#endif
  const float4 o = (float4)(fog_blend(c.x, k->fog_color.x, f), fog_blend(c.y, k->fog_color.y, f),
                            fog_blend(c.z, k->fog_color.z, f), c.w /* alpha passes through */);
#ifdef FOG_COLOR_HALF
  vstore_half4_rte(o, i, color_out);
#else
  vstore4(o, i, color_out);
#endif
}

/* One pixel at column x, row y: the GPU path and the row tails of the CPU path. */
static inline void fog_pixel(global const COLOR_T* color_in, global const float* depth,
                             global COLOR_T* color_out, size_t i, int x, int y,
                             const FogConstants* k) {
  float ray_length = 0.0f;
#if FOG_USE_DISTANCE
  const float u = fog_pixel_u((float)x, k->inv_width), v = fog_pixel_v((float)y, k->height);
  ray_length = fog_ray_length(fog_bilerp(k->bl.x, k->br.x, k->tl.x, k->tr.x, u, v),
                              fog_bilerp(k->bl.y, k->br.y, k->tl.y, k->tr.y, u, v),
                              fog_bilerp(k->bl.z, k->br.z, k->tl.z, k->tr.z, u, v));
#endif
  const float f = fog_factor(depth[i], ray_length, FOG_MODE, FOG_USE_DISTANCE, FOG_USE_SKYBOX,
                             FOG_USE_REVERSED_Z, FOG_PROJECTION, k->zx, k->zy, k->near_plane, k->far_plane,
                             k->k_a, k->k_b);
  fog_blend_pixel(color_in, color_out, i, f, k);
}

#if FOG_VECTOR_WIDTH == 16
#if defined(__clang__) && defined(__AVX512F__) && !defined(FOG_PORTABLE)
/* x86 AVX-512 (PoCL on such CPUs): compares straight into mask registers and 16-wide half
 * conversions. The portable fallbacks below compile everywhere; LLVM splits their half
 * conversions into 8-wide halves and their lane reductions into scalar chains. */
#define FOG_AVX512 1
typedef float fog_v16f __attribute__((__vector_size__(64)));
typedef short fog_v16h __attribute__((__vector_size__(32), aligned(2)));
#endif

/* Bit j set where lane j of f equals value. */
static inline uint fog_lanes_equal(float16 f, float value) {
#ifdef FOG_AVX512
  return __builtin_ia32_cmpps512_mask(__builtin_bit_cast(fog_v16f, f),
                                      __builtin_bit_cast(fog_v16f, (float16)value),
                                      0 /* _CMP_EQ_OQ */, (ushort)0xffff, 4 /* current rounding */);
#else
  const int16 bits = (f == value) & (int16)(0x1, 0x2, 0x4, 0x8, 0x10, 0x20, 0x40, 0x80, 0x100,
                                            0x200, 0x400, 0x800, 0x1000, 0x2000, 0x4000, 0x8000);
  const int8 a = bits.lo | bits.hi;
  const int4 b = a.lo | a.hi;
  const int2 c = b.lo | b.hi;
  return (uint)(c.x | c.y);
#endif
}

/* Quad q (4 pixels x RGBA) of the block starting at p, as floats. */
static inline float16 fog_load_quad(global const COLOR_T* p, uint q) {
#ifndef FOG_COLOR_HALF
  return vload16(q, p);
#elif defined(FOG_AVX512)
  return __builtin_bit_cast(float16, __builtin_ia32_vcvtph2ps512_mask(
      ((global const fog_v16h*)p)[q], (fog_v16f){}, (ushort)0xffff, 4 /* current rounding */));
#else
  return vload_half16(q, p);
#endif
}

static inline void fog_store_quad(float16 value, global COLOR_T* p, uint q) {
#ifndef FOG_COLOR_HALF
#if defined(FOG_STREAMING_STORES) && defined(__clang__)
  /* Streaming (non-temporal) stores where the quad is 64-byte aligned: the output is never read
   * by this pass, so skipping the read-for-ownership saves a third of the memory traffic of a
   * write. The driver's completion signalling (locked instructions) orders them for the host. */
  if ((((size_t)(p + 16 * q)) & 63) == 0) {
    __builtin_nontemporal_store(value, (global float16*)(p + 16 * q));
    return;
  }
#endif
  vstore16(value, q, p);
#elif defined(FOG_AVX512)
  ((global fog_v16h*)p)[q] = __builtin_ia32_vcvtps2ph512_mask(
      __builtin_bit_cast(fog_v16f, value), 0 /* round to nearest even */, (fog_v16h){}, (ushort)0xffff);
#else
  vstore_half16_rte(value, q, p);
#endif
}

/* Pixel j's factor in its R, G, B lanes and 1 in its alpha lane (q: pixels 4q..4q+3), which
 * makes fog_blend pass alpha through. Shuffle masks must be literal constants to become one
 * permute instruction. */
#define FOG_QUAD_FACTORS(f, q)                                                                \
  shuffle2(f, (float16)1.0f,                                                                  \
           (uint16)(4 * q, 4 * q, 4 * q, 16, 4 * q + 1, 4 * q + 1, 4 * q + 1, 16, 4 * q + 2, \
                    4 * q + 2, 4 * q + 2, 16, 4 * q + 3, 4 * q + 3, 4 * q + 3, 16))
#define FOG_ALPHA_LANES (int16)(0, 0, 0, -1, 0, 0, 0, -1, 0, 0, 0, -1, 0, 0, 0, -1)

/* 16 pixels of one row starting at frame index i0, column x0. Each block takes the cheapest
 * blend that gives fog_blend's result for its factors:
 *   every f == 1 (sky, or in front of a linear fog's start): the color's bits are copied;
 *   every f == 0 (beyond a linear fog's end, dense fog): fog color, alpha passed through;
 *   no f is 0 or 1: fog_blend_mix alone, no per-lane tests;
 *   mixed: fog_blend per lane; with half storage the f == 1 pixels are then copied over, since
 *   a half -> float -> half trip would quiet a signalling NaN. */
static inline void fog_pixels16(global const COLOR_T* color_in, global const float* depth,
                                global COLOR_T* color_out, size_t i0, int x0, int y,
                                const FogConstants* k) {
  float16 ray_length = 0.0f;
#if FOG_USE_DISTANCE
  const float16 lane = (float16)(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
  const float16 u = fog_pixel_u_v((float16)((float)x0) + lane, (float16)k->inv_width);
  const float16 v = (float16)fog_pixel_v((float)y, k->height);
  ray_length = fog_ray_length_v(
      fog_bilerp_v((float16)k->bl.x, (float16)k->br.x, (float16)k->tl.x, (float16)k->tr.x, u, v),
      fog_bilerp_v((float16)k->bl.y, (float16)k->br.y, (float16)k->tl.y, (float16)k->tr.y, u, v),
      fog_bilerp_v((float16)k->bl.z, (float16)k->br.z, (float16)k->tl.z, (float16)k->tr.z, u, v));
#endif
  const float16 f = fog_factor_v(vload16(0, depth + i0), ray_length, FOG_MODE, FOG_USE_DISTANCE,
                                 FOG_USE_SKYBOX, FOG_USE_REVERSED_Z, FOG_PROJECTION, (float16)k->zx,
                                 (float16)k->zy, (float16)k->near_plane, (float16)k->far_plane,
                                 (float16)k->k_a, (float16)k->k_b);
  global const COLOR_T* in = color_in + 4 * i0;
  global COLOR_T* out = color_out + 4 * i0;
  /* Copies as 32-bit words: rows need not start at a 64-byte boundary. */
  global const uint* in_bits = (global const uint*)in;
  global uint* out_bits = (global uint*)out;
  const uint keep = fog_lanes_equal(f, 1.0f);
  if (keep == 0xffffu) {
    for (uint w = 0; w < 16 * sizeof(COLOR_T); w += 16) vstore16(vload16(0, in_bits + w), 0, out_bits + w);
    return;
  }
  const float16 fog_rgba = (float16)(k->fog_color.xyz, 0.0f, k->fog_color.xyz, 0.0f,
                                     k->fog_color.xyz, 0.0f, k->fog_color.xyz, 0.0f);
  const uint fogged = fog_lanes_equal(f, 0.0f);
  if (fogged == 0xffffu) {
    for (uint q = 0; q < 4; ++q)
      fog_store_quad(select(fog_rgba, fog_load_quad(in, q), FOG_ALPHA_LANES), out, q);
    return;
  }
  if ((keep | fogged) == 0) {
#define FOG_QUAD_MIX(q)                                                                          \
  {                                                                                              \
    const float16 c = fog_load_quad(in, q);                                                      \
    fog_store_quad(select(fog_blend_mix_v(c, fog_rgba, FOG_QUAD_FACTORS(f, q)), c, FOG_ALPHA_LANES), \
                   out, q);                                                                      \
  }
    FOG_QUAD_MIX(0)
    FOG_QUAD_MIX(1)
    FOG_QUAD_MIX(2)
    FOG_QUAD_MIX(3)
#undef FOG_QUAD_MIX
    return;
  }
#define FOG_QUAD_BLEND(q) \
  fog_store_quad(fog_blend_v(fog_load_quad(in, q), fog_rgba, FOG_QUAD_FACTORS(f, q)), out, q);
  FOG_QUAD_BLEND(0)
  FOG_QUAD_BLEND(1)
  FOG_QUAD_BLEND(2)
  FOG_QUAD_BLEND(3)
#undef FOG_QUAD_BLEND
#ifdef FOG_COLOR_HALF
  for (uint j = 0; j < 16; ++j)
    if (keep & (1u << j)) vstore2(vload2(j, in_bits), j, out_bits);
#endif
}
#undef FOG_QUAD_FACTORS
#undef FOG_ALPHA_LANES
#endif

kernel void deferred_fog(global const COLOR_T* color_in, global const float* depth,
                         global COLOR_T* color_out, int width, int height,
                         float4 zbuffer_params, float4 projection_params, float4 corner_bl,
                         float4 corner_br, float4 corner_tl, float4 corner_tr,
                         float4 fog_params, float4 fog_color) {
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
