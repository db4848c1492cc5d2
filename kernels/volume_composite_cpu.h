/* volume_composite_cpu.h — the CPU devices' path of volume_composite.cl (VOL_LANES 16): 16 frame
 * pixels of a row per work-item. Kernel-only (OpenCL C); included by volume_composite.cl after
 * the float16 instance of fog_math.h (names _v) and fog_cpu_avx512.h; needs COLOR_T.
 *
 * Why: PoCL vectorises only across work-items, and the one-pixel kernel's branches (the A == 0
 * pass-through, the sky tests, the edge clamps) keep it scalar: 11-14x a memcpy. Here every
 * per-pixel decision is a select on lanes, so the pass is one straight run of SIMD code.
 *
 * Layouts. Weights are computed with one lane per pixel (float16 over the row's 16 pixels);
 * colors and the target's (P, A) as quads, 4 pixels x RGBA per float16, as in fog_cpu_blocks.h.
 * With x0 a multiple of 16 and s in {2, 4}, pixel j of the block samples the target columns
 * b + L_j and b + L_j + 1, b = x0 / s - 1, L_j = (j + s / 2) / s (vol_upsample_axis' floor of
 * (x + 0.5) / s - 0.5, clamps aside), and its bilinear fraction depends only on j % s (VOL_FX,
 * exact): every lane rounds like the one-pixel kernel and the C++ path
 * (tests/volume_composite_test.cpp compares the bits). Quad q of the block needs the 4 target
 * columns from b + 4q / s on: one float16 load per target row. Rows whose window reaches past the
 * target's edges load it column by column, clamped. Per-pixel float16s are kept in
 * VOL_PIXEL_ORDER (below), not the row's order.
 *
 * Rows. At s > 1 a work-item takes the s frame rows between two target rows (vol_rows_of): their
 * pixels sample the same two target rows, so the windows, the keys and the test for fog are
 * loaded and made once for s rows, and with the row's fraction (r + 1/2) / s a constant, the
 * rows are independent straight code: all s rows' weights first, then their quads
 * (docs/volumetric.md, "Lanes on CPU devices"). */

#ifdef __clang__
/* 16 words (halfwords) at 4-byte (2-byte) alignment, moved by one unaligned vector instruction (as
 * in fog_cpu_blocks.h: PoCL splits vstore16, into 16 scalar stores for ushort16). */
typedef uint vol_v16u_u __attribute__((__vector_size__(64), aligned(4)));
typedef ushort vol_v16h_u __attribute__((__vector_size__(32), aligned(2)));
#define VOL_STORE16U(value, p) (*(global vol_v16u_u*)(p) = __builtin_bit_cast(vol_v16u_u, (value)))
#define VOL_STORE16H(value, p) (*(global vol_v16h_u*)(p) = __builtin_bit_cast(vol_v16h_u, (value)))
#else
#define VOL_STORE16U(value, p) vstore16((value), 0, (p))
#define VOL_STORE16H(value, p) vstore16((value), 0, (p))
#endif
/* Quad q of the block's output, as bits (ushort16 of half storage, uint16 of float storage): RGBA32F
 * with streaming stores where the frame takes them (a macro, as FOG_STREAM_OR must stay). */
#ifdef FOG_COLOR_HALF
#define VOL_STORE_QUAD(bits, out, q, stream) VOL_STORE16H((bits), (global ushort*)(out) + 16 * (q))
#else
#define VOL_STORE_QUAD(bits, out, q, stream) \
  FOG_STREAM_OR((bits), (global uint*)(out) + 16 * (q), (stream), VOL_STORE16U((bits), (global uint*)(out) + 16 * (q)))
#endif

/* Shuffle masks (literal constants: one permute each, FOG_SHUFFLE). L_j, and within a quad's
 * 4-column window the column of each pixel's left tap (its right tap is the next one). VOL_FX:
 * pixel j's bilinear fraction, frac((j + 1/2) / s - 1/2), as literals (exact in binary, so they are
 * vol_upsample_axis' values; PoCL's floor would not fold at build time). */
#if VOL_SCALE == 2
#define VOL_LEFT_TAP 0, 1, 1, 2, 2, 3, 3, 4, 4, 5, 5, 6, 6, 7, 7, 8
#define VOL_RIGHT_TAP 1, 2, 2, 3, 3, 4, 4, 5, 5, 6, 6, 7, 7, 8, 8, 9
#define VOL_FX 0.75f, 0.25f, 0.75f, 0.25f, 0.75f, 0.25f, 0.75f, 0.25f, 0.75f, 0.25f, 0.75f, 0.25f, 0.75f, 0.25f, 0.75f, 0.25f
#define VOL_QUAD_LEFT 0, 1, 2, 3, 4, 5, 6, 7, 4, 5, 6, 7, 8, 9, 10, 11
#define VOL_QUAD_RIGHT 4, 5, 6, 7, 8, 9, 10, 11, 8, 9, 10, 11, 12, 13, 14, 15
#elif VOL_SCALE == 4
#define VOL_LEFT_TAP 0, 0, 1, 1, 1, 1, 2, 2, 2, 2, 3, 3, 3, 3, 4, 4
#define VOL_RIGHT_TAP 1, 1, 2, 2, 2, 2, 3, 3, 3, 3, 4, 4, 4, 4, 5, 5
#define VOL_FX 0.625f, 0.875f, 0.125f, 0.375f, 0.625f, 0.875f, 0.125f, 0.375f, 0.625f, 0.875f, 0.125f, 0.375f, 0.625f, 0.875f, 0.125f, 0.375f
#define VOL_QUAD_LEFT 0, 1, 2, 3, 0, 1, 2, 3, 4, 5, 6, 7, 4, 5, 6, 7
#define VOL_QUAD_RIGHT 4, 5, 6, 7, 4, 5, 6, 7, 8, 9, 10, 11, 8, 9, 10, 11
#endif
#define VOL_SHUFFLE(v, ...) FOG_SHUFFLE((v), (v), __VA_ARGS__)
/* Per-pixel float16s hold pixel 4q + k in lane 4k + q (VOL_PIXEL_ORDER of a row's natural order),
 * so that VOL_QUAD_SPREAD, quad q's 4 pixels each spread over its RGBA lanes (q a literal), stays
 * within 128-bit lanes: one vpermilps, not a cross-lane vpermps (-12 % for depth-aware RGBA16F). */
#define VOL_PIXEL_ORDER(v) VOL_SHUFFLE((v), 0, 4, 8, 12, 1, 5, 9, 13, 2, 6, 10, 14, 3, 7, 11, 15)
#define VOL_QUAD_SPREAD(v, q) \
  VOL_SHUFFLE((v), q, q, q, q, 4 + q, 4 + q, 4 + q, 4 + q, 8 + q, 8 + q, 8 + q, 8 + q, 12 + q, 12 + q, 12 + q, 12 + q)
#define VOL_QUAD_ALPHA(v) VOL_SHUFFLE((v), 3, 3, 3, 3, 7, 7, 7, 7, 11, 11, 11, 11, 15, 15, 15, 15)
#define VOL_ALPHA_LANES (int16)(0, 0, 0, -1, 0, 0, 0, -1, 0, 0, 0, -1, 0, 0, 0, -1)

/* vol_inverse_eye_depth (volume_composite.h) lane-wise: the same operations, selects for its branches. */
static inline float16 vol_inverse_eye_depth_v(float16 raw, global const float* frame) {
  const float16 depth = fog_sanitize_depth_v(raw, VOL_REVERSED_Z);
#if VOL_DEPTH_KIND != FOG_DEPTH_RAW
  int16 sky;
  const float16 rho =
      1.0f / fog_clamp_linear_depth_v(raw, (float16)frame[VOL_F_NEAR], (float16)frame[VOL_F_FAR], &sky);
#elif FOG_PROJECTION == FOG_PROJECTION_INFINITE_FAR
  const int16 sky = depth == 0.0f;
  const float16 rho = depth * frame[VOL_F_INV_NEAR];
#elif FOG_PROJECTION == FOG_PROJECTION_ORTHOGRAPHIC
  const float16 linear01 = fog_linear01_depth_ortho_v(depth, (float16)frame[VOL_F_ZX], (float16)frame[VOL_F_ZY]);
  const int16 sky = fog_is_sky_v(linear01);
  const float16 rho = 1.0f / (linear01 * frame[VOL_F_FAR]);
#else
  const float16 q =
      fog_linear01_denominator_v(depth, (float16)frame[VOL_F_ZX], (float16)frame[VOL_F_ZY], VOL_REVERSED_Z);
  const int16 sky = q < VOL_SKY_DENOMINATOR;
  const float16 rho = q * frame[VOL_F_INV_FAR];
#endif
  return select(select((float16)VOL_RHO_SKY, rho, rho > VOL_RHO_SKY), (float16)VOL_RHO_SKY, sky);
}

/* vol_depth_difference (volume_composite.h) lane-wise, in two steps: x = 1 - k rho of a capped key
 * (vol_capped_keys_v), then the difference min(|x|, 1). */
static inline float16 vol_capped_keys_v(float16 k) { return select((float16)VOL_KEY_SKY, k, k < VOL_KEY_SKY); }
static inline float16 vol_depth_x_v(float16 rho, float16 key) { return fma(-key, rho, (float16)1.0f); }
#if defined(FOG_AVX512) && defined(__AVX512DQ__)
/* vrangeps: of a and b the smaller (0x0a) or larger (0x0b) magnitude, sign cleared. With a quiet
 * NaN and a number it gives the number (Intel SDM, VRANGEPS, "Signaling of Comparison
 * Operations"). */
#define VOL_RANGE(a, b, imm)                                                                       \
  __builtin_bit_cast(float16, __builtin_ia32_rangeps512_mask(__builtin_bit_cast(fog_v16f, (a)),    \
                                                             __builtin_bit_cast(fog_v16f, (b)), (imm), \
                                                             (fog_v16f){}, (ushort)0xffff, 4 /* current rounding */))
#endif
static inline float16 vol_depth_difference_v(float16 x) {
#if defined(FOG_AVX512) && defined(__AVX512DQ__)
  /* min(|x|, 1) as one vrangeps, not and + min: -4..8 % for depth-aware RGBA16F. A NaN x (k rho =
   * 0 inf: a key of 0 and rho = inf, at an orthographic near plane at 0) is a quiet NaN: 1, as the
   * select does. */
  return VOL_RANGE(x, (float16)1.0f, 0x0a);
#else
  const float16 d = fabs(x);
  return select((float16)1.0f, d, d < 1.0f);
#endif
}

/* vol_upsample's own-surface test lane-wise: every difference min(|x_k|, 1) <= EPS. With AVX-512
 * three vrangeps take the largest |x_k| and one compare tests it: a NaN x_k (k rho = 0 inf) has
 * rho = inf, where every x is NaN or -inf, so the largest is NaN or inf and the test fails as the
 * differences' (1 > EPS) does. */
static inline int16 vol_own_surface_v(float16 x0, float16 x1, float16 x2, float16 x3) {
#if defined(FOG_AVX512) && defined(__AVX512DQ__)
  return VOL_RANGE(VOL_RANGE(x0, x1, 0x0b), VOL_RANGE(x2, x3, 0x0b), 0x0b) <= VOL_UPSAMPLE_EPS;
#else
  return max(max(vol_depth_difference_v(x0), vol_depth_difference_v(x1)),
             max(vol_depth_difference_v(x2), vol_depth_difference_v(x3))) <= VOL_UPSAMPLE_EPS;
#endif
}

/* A target row's window for a block, as values (no private arrays: PoCL gives those a copy per
 * work-item of the work-group, past L1): 4 columns of (P, A) from column c, and the depth keys of
 * columns b .. b + 15. Blocks whose window reaches past the row (the frame's first and last
 * blocks) gather it column by column with the edge clamp. */
#define VOL_COLUMN(c) vload4(0, low + 4 * (at + (size_t)clamp((c), 0, low_width - 1)))
static inline __attribute__((always_inline)) float16 vol_window_rgba(global const float* low, size_t at, int c, int low_width, int inside) {
  if (inside) return vload16(0, low + 4 * (at + (size_t)c));
  return (float16)(VOL_COLUMN(c), VOL_COLUMN(c + 1), VOL_COLUMN(c + 2), VOL_COLUMN(c + 3));
}
#undef VOL_COLUMN
#define VOL_KEY(c) low_key[at + (size_t)clamp(b + (c), 0, low_width - 1)]
static inline __attribute__((always_inline)) float16 vol_window_keys(global const float* low_key, size_t at, int b, int low_width, int inside) {
  if (inside) return vload16(0, low_key + at + (size_t)b);
  return (float16)(VOL_KEY(0), VOL_KEY(1), VOL_KEY(2), VOL_KEY(3), VOL_KEY(4), VOL_KEY(5), VOL_KEY(6), VOL_KEY(7),
                   VOL_KEY(8), VOL_KEY(9), VOL_KEY(10), VOL_KEY(11), VOL_KEY(12), VOL_KEY(13), VOL_KEY(14),
                   VOL_KEY(15));
}
#undef VOL_KEY

/* Quad q of the block unchanged: the pass-through of a quad with no fog, as bits. */
static inline void vol_copy_quad(global const COLOR_T* in, global COLOR_T* out, uint q, int stream) {
#ifdef FOG_COLOR_HALF
  const ushort16 bits = vload16(q, (global const ushort*)in);
#else
  const uint16 bits = vload16(q, (global const uint*)in);
#endif
  VOL_STORE_QUAD(bits, out, q, stream);
}

/* Whether none of the (P, A) quads of a block's window has fog: every coverage is +0, so every
 * pixel's upsampled coverage is 0 (its weights are positive and finite) and the composite passes
 * the input through. -0 and NaN coverages take the full path, which gives them the same bits. */
static inline int vol_fogless(float16 t0, float16 t1, float16 t2, float16 t3) {
  const uint16 bits = (as_uint16(t0) | as_uint16(t1) | as_uint16(t2) | as_uint16(t3)) & as_uint16(VOL_ALPHA_LANES);
  return !VOL_ANY16(bits != 0u);
}

/* vol_composite's channel rule on a quad: fma(c, 1 - a, fog), fog where a == 1. With AVX-512 one
 * fma whose mask keeps fog (vfmadd231ps {k}), not an fma and a blend. */
static inline float16 vol_over(float16 c, float16 a, float16 fog) {
#ifdef FOG_AVX512
  const ushort not_opaque = __builtin_ia32_cmpps512_mask(
      __builtin_bit_cast(fog_v16f, a), __builtin_bit_cast(fog_v16f, (float16)1.0f), 0x04 /* _CMP_NEQ_UQ */,
      (ushort)0xffff, 4 /* current rounding */);
  return __builtin_bit_cast(float16, __builtin_ia32_vfmaddps512_mask3(
      __builtin_bit_cast(fog_v16f, c), __builtin_bit_cast(fog_v16f, 1.0f - a), __builtin_bit_cast(fog_v16f, fog),
      not_opaque, 4 /* current rounding */));
#else
  return select(fma(c, 1.0f - a, fog), fog, a == 1.0f);
#endif
}

/* Quad q of the block as bits: the composite where 0 < A, the input's bits where A == 0 and in
 * the alpha lanes (vol_composite's rules; A == 1 writes P exactly). */
static inline void vol_composite_quad(global const COLOR_T* in, global COLOR_T* out, uint q, float16 fog,
                                      int stream) {
  const float16 a = VOL_QUAD_ALPHA(fog);
  const int16 keep = (a == 0.0f) | VOL_ALPHA_LANES;
#ifdef FOG_COLOR_HALF
  const ushort16 bits = vload16(q, (global const ushort*)in);
#ifdef FOG_AVX512
  const float16 c = __builtin_bit_cast(float16, __builtin_ia32_vcvtph2ps512_mask(
      __builtin_bit_cast(fog_v16h, bits), (fog_v16f){}, (ushort)0xffff, 4 /* current rounding */));
#else
  const float16 c = vload_half16(q, in);
#endif
  const float16 o = vol_over(c, a, fog);
#ifdef FOG_AVX512
  const ushort16 rounded = __builtin_bit_cast(ushort16, __builtin_ia32_vcvtps2ph512_mask(
      __builtin_bit_cast(fog_v16f, o), 0 /* round to nearest even */, (fog_v16h){}, (ushort)0xffff));
#else
  ushort staged[16]; /* vstore_half has no register form: round through private memory */
  vstore_half16_rte(o, 0, (half*)staged);
  const ushort16 rounded = vload16(0, staged);
#endif
  VOL_STORE_QUAD(select(rounded, bits, convert_short16(keep)), out, q, stream);
#else
  const uint16 bits = vload16(q, (global const uint*)in);
  const float16 c = as_float16(bits);
  const float16 o = vol_over(c, a, fog);
  const uint16 result = select(as_uint16(o), bits, keep);
  VOL_STORE_QUAD(result, out, q, stream);
#endif
}

#if VOL_SCALE == 1
/* 16 pixels of row y from column x0 (a multiple of 16, x0 + 16 <= width), frame index i0: the
 * target is the frame's own resolution, each pixel's own sample, unchanged. */
static inline void vol_composite16(global const COLOR_T* color_in, global COLOR_T* color_out, global const float* low,
                                   size_t i0, int stream) {
  global const COLOR_T* in = color_in + 4 * i0;
  global COLOR_T* out = color_out + 4 * i0;
  const float16 f0 = vload16(0, low + 4 * i0), f1 = vload16(1, low + 4 * i0), f2 = vload16(2, low + 4 * i0),
                f3 = vload16(3, low + 4 * i0);
  if (vol_fogless(f0, f1, f2, f3)) {
    for (uint q = 0; q < 4; ++q) vol_copy_quad(in, out, q, stream);
    return;
  }
  vol_composite_quad(in, out, 0, f0, stream);
  vol_composite_quad(in, out, 1, f1, stream);
  vol_composite_quad(in, out, 2, f2, stream);
  vol_composite_quad(in, out, 3, f3, stream);
}
#else
/* The frame rows between target rows m - 1 and m: rows s m - s / 2 .. s m + s / 2 - 1, those
 * inside the frame, in [*first, *last). Their pixels sample target rows m - 1 and m (edges
 * clamp: vol_upsample_axis), so one work-item loads the target's windows and keys, and tests for
 * fog, once for s rows. */
static inline void vol_rows_of(int m, int height, int* first, int* last) {
  *first = max(VOL_SCALE * m - VOL_SCALE / 2, 0);
  *last = min(VOL_SCALE * m + VOL_SCALE / 2, height);
}

/* 16 pixels from column x0 (a multiple of 16, x0 + 16 <= width) of each frame row of target row
 * pair m (vol_rows_of). */
static inline void vol_composite16(global const COLOR_T* color_in, global const float* depth,
                                   global COLOR_T* color_out, global const float* frame, global const float* low,
                                   global const float* low_key, int x0, int m, int width, int height, int stream) {
  int first, last;
  vol_rows_of(m, height, &first, &last);
  const int low_width = (int)frame[VOL_F_LOW_WIDTH], low_height = (int)frame[VOL_F_LOW_HEIGHT];
  const int b = x0 / VOL_SCALE - 1;
  const int inside = b >= 0 && b + 15 < low_width; /* the keys' load reaches b + 15 */
  const size_t top = (size_t)max(m - 1, 0) * (size_t)low_width, bottom = (size_t)min(m, low_height - 1) * (size_t)low_width;
  /* The target's windows of the 4 quads (quad q from column b + 4q / s), in the top and bottom rows. */
#define VOL_WINDOW(row, q) vol_window_rgba(low, (row), b + 4 * (q) / VOL_SCALE, low_width, inside)
  const float16 t0 = VOL_WINDOW(top, 0), t1 = VOL_WINDOW(top, 1), t2 = VOL_WINDOW(top, 2), t3 = VOL_WINDOW(top, 3);
  const float16 u0 = VOL_WINDOW(bottom, 0), u1 = VOL_WINDOW(bottom, 1), u2 = VOL_WINDOW(bottom, 2),
                u3 = VOL_WINDOW(bottom, 3);
#undef VOL_WINDOW
  /* Blocks away from the volumes (most of a frame, usually) are a copy: no depth, no weights. */
  if (vol_fogless(t0, t1, t2, t3) && vol_fogless(u0, u1, u2, u3)) {
    for (int y = first; y < last; ++y) {
      const size_t i0 = (size_t)y * (size_t)width + (size_t)x0;
      for (uint q = 0; q < 4; ++q) vol_copy_quad(color_in + 4 * i0, color_out + 4 * i0, q, stream);
    }
    return;
  }
  const float16 fx = VOL_PIXEL_ORDER((float16)(VOL_FX));
#if VOL_DEPTH_AWARE
  const float16 top_keys = vol_capped_keys_v(vol_window_keys(low_key, top, b, low_width, inside));
  const float16 bottom_keys = vol_capped_keys_v(vol_window_keys(low_key, bottom, b, low_width, inside));
#endif
  /* Row r of the s (r a literal or the loop's index, named by the token n): its frame index i0_n and
   * vol_upsample's bilinear weights w0_n .. w3_n with vol_upsample_axis' fraction (r + 1/2) / s (a
   * constant, clamps or not); depth-aware, also the taps' x0_n .. x3_n (vol_depth_x_v) and own_n,
   * the pixels whose four differences are within EPS (vol_upsample's bilinear case). */
#define VOL_ROW_WEIGHTS(n, r)                                                                         \
  const size_t i0_##n = (size_t)(VOL_SCALE * m - VOL_SCALE / 2 + (r)) * (size_t)width + (size_t)x0;   \
  const float fy_##n = ((float)(r) + 0.5f) / (float)VOL_SCALE;                                        \
  float16 w0_##n = (1.0f - fx) * (1.0f - fy_##n), w1_##n = fx * (1.0f - fy_##n),                      \
          w2_##n = (1.0f - fx) * fy_##n, w3_##n = fx * fy_##n;                                        \
  VOL_DEPTH_DIFFERENCES(n)
#if VOL_DEPTH_AWARE
#define VOL_X(keys, tap) vol_depth_x_v(rho, VOL_PIXEL_ORDER(VOL_SHUFFLE(keys, tap)))
#define VOL_DEPTH_DIFFERENCES(n)                                                                      \
  float16 x0_##n, x1_##n, x2_##n, x3_##n;                                                             \
  {                                                                                                   \
    const float16 rho = vol_inverse_eye_depth_v(VOL_PIXEL_ORDER(vload16(0, depth + i0_##n)), frame);  \
    x0_##n = VOL_X(top_keys, VOL_LEFT_TAP);                                                           \
    x1_##n = VOL_X(top_keys, VOL_RIGHT_TAP);                                                          \
    x2_##n = VOL_X(bottom_keys, VOL_LEFT_TAP);                                                        \
    x3_##n = VOL_X(bottom_keys, VOL_RIGHT_TAP);                                                       \
  }                                                                                                   \
  const int16 own_##n = vol_own_surface_v(x0_##n, x1_##n, x2_##n, x3_##n);
/* Depth-aware row n where some pixel has a tap off its surface: the weights times the other taps'
 * e = max(difference, EPS), norm_n the reciprocal of their sum; own_n's pixels keep the bilinear
 * weights and a norm of 1 (x 1 is exact: their bits are vol_upsample's unnormalised ones). */
#define VOL_E(x) max(vol_depth_difference_v(x), (float16)VOL_UPSAMPLE_EPS)
#define VOL_DEPTH_WEIGHTS(n)                                                                          \
  float16 norm_##n;                                                                                   \
  {                                                                                                   \
    const float16 e0 = VOL_E(x0_##n), e1 = VOL_E(x1_##n), e2 = VOL_E(x2_##n), e3 = VOL_E(x3_##n);     \
    const float16 e01 = e0 * e1, e23 = e2 * e3;                                                       \
    const float16 p0 = w0_##n * (e1 * e23), p1 = w1_##n * (e0 * e23);                                 \
    const float16 p2 = w2_##n * (e3 * e01), p3 = w3_##n * (e2 * e01);                                 \
    norm_##n = select(1.0f / ((p0 + p1) + (p2 + p3)), (float16)1.0f, own_##n);                        \
    w0_##n = select(p0, w0_##n, own_##n);                                                             \
    w1_##n = select(p1, w1_##n, own_##n);                                                             \
    w2_##n = select(p2, w2_##n, own_##n);                                                             \
    w3_##n = select(p3, w3_##n, own_##n);                                                             \
  }
#define VOL_ALL_OWN(n) (!VOL_ANY16(~own_##n))
#define VOL_NORMALISED(sum, q, n) ((sum) * VOL_QUAD_SPREAD(norm_##n, q))
#else
#define VOL_DEPTH_DIFFERENCES(n)
#endif
#define VOL_AS_IS(sum, q, n) (sum) /* the bilinear weights sum to exactly 1 */
  /* vol_upsample's sum for quad q of row n: the top row's taps, the bottom row's, their sum,
   * normalised (NORM: VOL_NORMALISED or VOL_AS_IS; last, so the division's latency overlaps the
   * taps' arithmetic). */
#define VOL_QUAD(q, t, u, n, NORM)                                                                    \
  {                                                                                                   \
    const float16 top_taps = fma(VOL_SHUFFLE(t, VOL_QUAD_RIGHT), VOL_QUAD_SPREAD(w1_##n, q),          \
                                 VOL_SHUFFLE(t, VOL_QUAD_LEFT) * VOL_QUAD_SPREAD(w0_##n, q));          \
    const float16 bottom_taps = fma(VOL_SHUFFLE(u, VOL_QUAD_RIGHT), VOL_QUAD_SPREAD(w3_##n, q),       \
                                    VOL_SHUFFLE(u, VOL_QUAD_LEFT) * VOL_QUAD_SPREAD(w2_##n, q));       \
    vol_composite_quad(color_in + 4 * i0_##n, color_out + 4 * i0_##n, q,                              \
                       NORM(top_taps + bottom_taps, q, n), stream);                                   \
  }
#define VOL_ROW_QUADS(n, NORM) \
  VOL_QUAD(0, t0, u0, n, NORM) VOL_QUAD(1, t1, u1, n, NORM) VOL_QUAD(2, t2, u2, n, NORM) VOL_QUAD(3, t3, u3, n, NORM)
  /* The s rows of the straight path, each macro X applied to row r = 0 .. s - 1 (named r too). */
#if VOL_SCALE == 4
#define VOL_EACH_ROW(X) X(0) X(1) X(2) X(3)
#else
#define VOL_EACH_ROW(X) X(0) X(1)
#endif
#define VOL_ROW_WEIGHTS_AT(r) VOL_ROW_WEIGHTS(r, r)
#define VOL_AND_ALL_OWN(n) && VOL_ALL_OWN(n)
#define VOL_ROW_QUADS_NORMALISED(n) VOL_ROW_QUADS(n, VOL_NORMALISED)
#define VOL_ROW_QUADS_AS_IS(n) VOL_ROW_QUADS(n, VOL_AS_IS)
  /* All s rows in the frame (every pair but the frame's first and last): the rows' weights first,
   * then their quads, so that each row's chain (depth, weights, division) overlaps the others'.
   * Depth-aware blocks all of whose pixels are on their taps' surface (most of a frame: 84 % of
   * the 1080p demo's) are bilinear: no products, no division, no normalisation. */
  if (first == VOL_SCALE * m - VOL_SCALE / 2 && last == VOL_SCALE * m + VOL_SCALE / 2) {
    VOL_EACH_ROW(VOL_ROW_WEIGHTS_AT)
#if VOL_DEPTH_AWARE
    if (!(1 VOL_EACH_ROW(VOL_AND_ALL_OWN))) {
      VOL_EACH_ROW(VOL_DEPTH_WEIGHTS)
      VOL_EACH_ROW(VOL_ROW_QUADS_NORMALISED)
      return;
    }
#endif
    VOL_EACH_ROW(VOL_ROW_QUADS_AS_IS)
    return;
  }
#pragma unroll
  for (int r = 0; r < VOL_SCALE; ++r) {
    const int y = VOL_SCALE * m - VOL_SCALE / 2 + r;
    if (y < first || y >= last) continue;
    VOL_ROW_WEIGHTS(row, r)
#if VOL_DEPTH_AWARE
    VOL_DEPTH_WEIGHTS(row)
    VOL_ROW_QUADS(row, VOL_NORMALISED)
#else
    VOL_ROW_QUADS(row, VOL_AS_IS)
#endif
  }
#undef VOL_ROW_QUADS
#undef VOL_EACH_ROW
#undef VOL_ROW_WEIGHTS_AT
#undef VOL_AND_ALL_OWN
#undef VOL_ROW_QUADS_NORMALISED
#undef VOL_ROW_QUADS_AS_IS
#undef VOL_QUAD
#undef VOL_ROW_WEIGHTS
#undef VOL_DEPTH_DIFFERENCES
#undef VOL_DEPTH_WEIGHTS
#undef VOL_X
#undef VOL_RANGE
#undef VOL_E
#undef VOL_ALL_OWN
#undef VOL_NORMALISED
#undef VOL_AS_IS
}
#endif

#undef VOL_STORE_QUAD
#undef VOL_QUAD_SPREAD
#undef VOL_PIXEL_ORDER
#undef VOL_QUAD_ALPHA
#undef VOL_ALPHA_LANES
