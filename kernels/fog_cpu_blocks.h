/* fog_cpu_blocks.h — the CPU devices' path of deferred_fog.cl (FOG_VECTOR_WIDTH 16): 16 pixels
 * of a row per work-item, as float16 lanes, and the four per-block blends. Included by
 * deferred_fog.cl after the formula instances and FogConstants; needs COLOR_T and
 * fog_cpu_avx512.h. Under FOG_AVX512 (x86 AVX-512) compares go straight into mask registers and
 * half conversions are 16 wide; the portable fallbacks compile everywhere, but LLVM splits their
 * half conversions into 8-wide halves and their lane reductions into scalar chains. */
#ifdef __clang__
/* 16 words at 4-byte alignment, moved by one unaligned vector instruction: PoCL lowers
 * vstore16 to three stores (16 + 16 + 32 bytes) and splits vload16 of uint into four loads. */
typedef float fog_v16f_u __attribute__((__vector_size__(64), aligned(4)));
typedef uint fog_v16u_u __attribute__((__vector_size__(64), aligned(4)));
#define FOG_STORE16(value, p) (*(global fog_v16f_u*)(p) = __builtin_bit_cast(fog_v16f_u, (value)))
#define FOG_COPY16(from, to) (*(global fog_v16u_u*)(to) = *(global const fog_v16u_u*)(from))
#else
#define FOG_STORE16(value, p) vstore16((value), 0, (p))
#define FOG_COPY16(from, to) vstore16(vload16(0, (from)), 0, (to))
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

static inline void fog_store_quad(float16 value, global COLOR_T* p, uint q, const FogConstants* k) {
#ifndef FOG_COLOR_HALF
  FOG_STREAM_OR(as_uint16(value), (global uint*)(p + 16 * q), k->stream, FOG_STORE16(value, p + 16 * q));
#elif defined(FOG_AVX512)
  ((global fog_v16h*)p)[q] = __builtin_ia32_vcvtps2ph512_mask(
      __builtin_bit_cast(fog_v16f, value), 0 /* round to nearest even */, (fog_v16h){}, (ushort)0xffff);
#else
  vstore_half16_rte(value, q, p);
#endif
}

/* A block's 16 pixels copied bit for bit (as 32-bit words: rows need not start at a 64-byte
 * boundary). */
static inline void fog_copy_block(global const uint* in_bits, global uint* out_bits, const FogConstants* k) {
  for (uint w = 0; w < 16 * sizeof(COLOR_T); w += 16)
    FOG_STREAM_OR(__builtin_bit_cast(uint16, *(global const fog_v16u_u*)(in_bits + w)), out_bits + w, k->stream,
                  FOG_COPY16(in_bits + w, out_bits + w));
}

/* Half storage: the pixels whose bit j is set in `keep` copied back over the block's stores, bit
 * for bit (a half -> float -> half trip would quiet a signalling NaN). */
static inline void fog_restore_kept(uint keep, global const uint* in_bits, global uint* out_bits) {
  for (uint j = 0; j < 16; ++j)
    if (keep & (1u << j)) vstore2(vload2(j, in_bits), j, out_bits);
}

/* Pixel j's factor in its R, G, B lanes and 1 in its alpha lane (q: pixels 4q..4q+3, a literal),
 * which makes fog_blend pass alpha through. */
#define FOG_QUAD_FACTORS(f, q)                                                                     \
  FOG_SHUFFLE(f, (float16)1.0f, 4 * q, 4 * q, 4 * q, 16, 4 * q + 1, 4 * q + 1, 4 * q + 1, 16, 4 * q + 2, \
              4 * q + 2, 4 * q + 2, 16, 4 * q + 3, 4 * q + 3, 4 * q + 3, 16)
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
  float16 ray = 0.0f;
#if FOG_USE_RAY
  const float16 lane = (float16)(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
  const float16 u = fog_pixel_u_v((float16)((float)x0) + lane, (float16)k->inv_width);
  const float16 v = (float16)fog_pixel_v((float)y, k->height);
  ray = fog_ray_term_v(
      fog_bilerp_v((float16)k->bl.x, (float16)k->br.x, (float16)k->tl.x, (float16)k->tr.x, u, v),
      fog_bilerp_v((float16)k->bl.y, (float16)k->br.y, (float16)k->tl.y, (float16)k->tr.y, u, v),
      fog_bilerp_v((float16)k->bl.z, (float16)k->br.z, (float16)k->tl.z, (float16)k->tr.z, u, v),
      FOG_USE_SQUARED);
#endif
  const float16 f = fog_factor_v(vload16(0, depth + i0), ray, FOG_DEPTH_KIND, FOG_MODE, FOG_USE_DISTANCE,
                                 FOG_USE_SKYBOX, FOG_USE_SKY_INFINITE, FOG_USE_REVERSED_Z, FOG_PROJECTION, (float16)k->zx,
                                 (float16)k->zy, (float16)k->near_plane, (float16)k->far_plane,
                                 (float16)k->k_a, (float16)k->k_b);
  global const COLOR_T* in = color_in + 4 * i0;
  global COLOR_T* out = color_out + 4 * i0;
  /* Copies as 32-bit words: rows need not start at a 64-byte boundary. */
  global const uint* in_bits = (global const uint*)in;
  global uint* out_bits = (global uint*)out;
  const uint keep = fog_lanes_equal(f, 1.0f);
  if (keep == 0xffffu) {
    fog_copy_block(in_bits, out_bits, k);
    return;
  }
  const float16 fog_rgba = (float16)(k->fog_color.xyz, 0.0f, k->fog_color.xyz, 0.0f,
                                     k->fog_color.xyz, 0.0f, k->fog_color.xyz, 0.0f);
  const uint fogged = fog_lanes_equal(f, 0.0f);
  if (fogged == 0xffffu) {
    for (uint q = 0; q < 4; ++q)
      fog_store_quad(select(fog_rgba, fog_load_quad(in, q), FOG_ALPHA_LANES), out, q, k);
    return;
  }
  if ((keep | fogged) == 0) {
#define FOG_QUAD_MIX(q)                                                                          \
  {                                                                                              \
    const float16 c = fog_load_quad(in, q);                                                      \
    fog_store_quad(select(fog_blend_mix_v(c, fog_rgba, FOG_QUAD_FACTORS(f, q)), c, FOG_ALPHA_LANES), \
                   out, q, k);                                                                   \
  }
    FOG_QUAD_MIX(0)
    FOG_QUAD_MIX(1)
    FOG_QUAD_MIX(2)
    FOG_QUAD_MIX(3)
#undef FOG_QUAD_MIX
    return;
  }
#define FOG_QUAD_BLEND(q) \
  fog_store_quad(fog_blend_v(fog_load_quad(in, q), fog_rgba, FOG_QUAD_FACTORS(f, q)), out, q, k);
  FOG_QUAD_BLEND(0)
  FOG_QUAD_BLEND(1)
  FOG_QUAD_BLEND(2)
  FOG_QUAD_BLEND(3)
#undef FOG_QUAD_BLEND
#ifdef FOG_COLOR_HALF
  fog_restore_kept(keep, in_bits, out_bits);
#endif
}
#undef FOG_QUAD_FACTORS
#undef FOG_ALPHA_LANES
#undef FOG_STORE16
#undef FOG_COPY16
#undef FOG_AVX512
