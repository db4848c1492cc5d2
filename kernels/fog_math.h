/* fog_math.h — the per-pixel formulas of docs/DESIGN.md §2, written once and compiled three ways:
 *   - OpenCL C on one pixel:       FOG_REAL float,   FOG_INT int,   FOG_NAME(f) f
 *   - OpenCL C on 16 pixels:       FOG_REAL float16, FOG_INT int16, FOG_NAME(f) f##_v
 *     (vector lanes are independent pixels; every operation is lane-wise IEEE, so a lane rounds
 *     exactly like the scalar version);
 *   - C++ (src/pass/scalar_fog.cpp): FOG_FN makes each function a template on FOG_REAL, so the
 *     same text runs in float for the baseline and in double for the reference.
 * In OpenCL C this file defines the instance's macros itself (below): the one-pixel instance, or
 * the 16-pixel one when the includer defines FOG_LANES16; the includer defines FOG_EXP2 and may
 * define the optional hooks FOG_CEIL and FOG_EXP2_LDEXP. In C++ the includer defines FOG_INT,
 * FOG_NAME, FOG_TRUNC_INT, FOG_TO_REAL and FOG_AS_REAL. This file has no include guard on purpose
 * and undefines the instance macros (not FOG_EXP2) at its end. Only operations that exist in both languages
 * appear: + - * /, fma, expm1, sqrt, fmin, fmax, integer + and <<, a float -> int conversion, and
 * ?: (a per-lane select on vectors in OpenCL C), besides the optional hooks.
 * Sources: Unity's UnityCG.cginc (Linear01Depth, UNITY_CALC_FOG_FACTOR_RAW) and Catlike Coding,
 * "Rendering 14: Fog" (deferred fog, depth vs distance, the skybox test). */

#ifndef FOG_FN
#ifdef __OPENCL_C_VERSION__
#define FOG_FN static inline
#else
#define FOG_FN template <typename FOG_REAL> inline
#endif
#endif

/* The OpenCL C instances: lanes are independent pixels, names of the 16-pixel one end in _v. */
#if defined(__OPENCL_C_VERSION__) && !defined(FOG_REAL)
#ifdef FOG_LANES16
#define FOG_REAL float16
#define FOG_INT int16
#define FOG_AS_UINT as_uint16
#define FOG_TRUNC_INT convert_int16
#define FOG_TO_REAL convert_float16
#define FOG_AS_REAL as_float16
#define FOG_NAME(name) name##_v
#else
#define FOG_REAL float
#define FOG_INT int
#define FOG_AS_UINT as_uint
#define FOG_TRUNC_INT convert_int
#define FOG_TO_REAL convert_float
#define FOG_AS_REAL as_float
#define FOG_NAME(name) name
#endif
#endif

/* Fog modes (FOG_MODE in the kernel, KernelMode on the host) and projections (Projection). */
#ifndef FOG_MODE_LINEAR
#define FOG_MODE_LINEAR 1
#define FOG_MODE_STEP 2
#define FOG_MODE_EXP 3
#define FOG_MODE_EXP2 4
#define FOG_PROJECTION_PERSPECTIVE 0
#define FOG_PROJECTION_INFINITE_FAR 1
#define FOG_PROJECTION_ORTHOGRAPHIC 2
/* What the depth buffer holds (FOG_DEPTH_KIND in the kernel, DepthKind on the host). */
#define FOG_DEPTH_RAW 0
#define FOG_DEPTH_EYE 1
#define FOG_DEPTH_DISTANCE 2
/* Distance-based exp2 fog works on the squared view distance q = d^2, which it needs anyway, so
 * it takes no square root of |ray|^2 (a vector sqrt costs the CPU path about 4 cycles per 16
 * pixels). Everything else works on q = d. */
#define FOG_SQUARED(mode, distance) ((mode) == FOG_MODE_EXP2 && (distance))
#endif

/* Pixel centre to Unity uv: u grows to the right, v grows upwards (row 0 is the top row).
 * x, y are pixel indices converted to FOG_REAL (exact below 2^24). u multiplies by the
 * per-frame 1 / width: a division per pixel costs more than the half ulp it would save. */
FOG_FN FOG_REAL FOG_NAME(fog_pixel_u)(FOG_REAL x, FOG_REAL inv_width) {
  return (x + (FOG_REAL)0.5f) * inv_width;
}
FOG_FN FOG_REAL FOG_NAME(fog_pixel_v)(FOG_REAL y, FOG_REAL height) {
  return (FOG_REAL)1 - (y + (FOG_REAL)0.5f) / height;
}

/* One component of the pixel's far-plane ray: the bilinear interpolation of the corners
 * (bottom-left, bottom-right, top-left, top-right) at (u, v), as the rasterised full-screen quad
 * does. Interpolated along v first: left and right depend on the row only, so a row of pixels
 * costs one multiply-add per component. */
FOG_FN FOG_REAL FOG_NAME(fog_bilerp)(FOG_REAL bl, FOG_REAL br, FOG_REAL tl, FOG_REAL tr,
                                     FOG_REAL u, FOG_REAL v) {
  FOG_REAL left = fma(tl - bl, v, bl);
  FOG_REAL right = fma(tr - br, v, br);
  return fma(right - left, u, left);
}

/* The ray term fog_view_distance takes: |ray|, or |ray|^2 where `squared` (FOG_SQUARED). */
FOG_FN FOG_REAL FOG_NAME(fog_ray_term)(FOG_REAL rx, FOG_REAL ry, FOG_REAL rz, int squared) {
  FOG_REAL length2 = fma(rx, rx, fma(ry, ry, rz * rz));
  return squared ? length2 : sqrt(length2);
}

/* NaN test that survives -cl-fast-relaxed-math (which may fold x != x away): the bit pattern.
 * The includer of an OpenCL instance defines FOG_AS_UINT (as_uint, as_uint16). */
#ifdef __OPENCL_C_VERSION__
#define FOG_IS_NAN(x) ((FOG_AS_UINT(x) & 0x7fffffffu) > 0x7f800000u)
#else
#define FOG_IS_NAN(x) isnan(x)
#endif

/* Raw depth outside [0, 1] is clamped; NaN becomes the far value (sky). Two implementations,
 * the same results:
 * - FOG_CLAMP_BY_SELECT (includers whose compiler keeps IEEE comparisons: LLVM on CPU devices,
 *   C++): compare-and-select towards the far end first. A comparison with NaN is false, so NaN
 *   takes the far value at the first select and the second never sees one; two min/max
 *   instructions on x86.
 * - otherwise, and always under -cl-fast-relaxed-math (which lets the compiler assume no NaN):
 *   NaN is tested on its bits and replaced after an fmin/fmax clamp. NVIDIA's compiler turns a
 *   clamp into a saturate, which sends NaN to 0 (the near plane), even the compare-and-select
 *   form above: an H100 run of the suite caught both. */
FOG_FN FOG_REAL FOG_NAME(fog_sanitize_depth)(FOG_REAL raw, int reversed_z) {
#if defined(FOG_CLAMP_BY_SELECT) && !defined(__FAST_RELAXED_MATH__)
  if (reversed_z) {
    FOG_REAL t = raw > (FOG_REAL)0 ? raw : (FOG_REAL)0;
    return t < (FOG_REAL)1 ? t : (FOG_REAL)1;
  }
  FOG_REAL t = raw < (FOG_REAL)1 ? raw : (FOG_REAL)1;
  return t > (FOG_REAL)0 ? t : (FOG_REAL)0;
#else
  FOG_REAL clamped = fmin(fmax(raw, (FOG_REAL)0), (FOG_REAL)1);
  return FOG_IS_NAN(raw) ? (FOG_REAL)(reversed_z ? 0.0f : 1.0f) : clamped;
#endif
}

/* Linear01Depth = 1 / (x * raw + y), evaluated without cancellation. Conventional Z has
 * x = 1 - y, so x * raw + y = y * (1 - raw) + raw: two non-negative terms and one rounding in the
 * fma (1 - raw is exact for raw >= 0.5). The textbook form cancels for far pixels (x * raw ~ -y,
 * costing up to far/near ulps) and breaks outright once far/near >= 2^24, where float x = 1 - y
 * has lost its 1 and x + y = 0. Reversed Z (y = 1, x = far/near - 1 > 0) adds two positive
 * terms already. */
FOG_FN FOG_REAL FOG_NAME(fog_linear01_denominator)(FOG_REAL raw, FOG_REAL zx, FOG_REAL zy, int reversed_z) {
  return reversed_z ? fma(zx, raw, zy) : fma(zy, (FOG_REAL)1 - raw, raw);
}
FOG_FN FOG_REAL FOG_NAME(fog_linear01_depth)(FOG_REAL raw, FOG_REAL zx, FOG_REAL zy, int reversed_z) {
  return (FOG_REAL)1 / FOG_NAME(fog_linear01_denominator)(raw, zx, zy, reversed_z);
}

/* Orthographic depth is linear: Linear01Depth = x * raw + y (lerp(near, far, raw) / far). */
FOG_FN FOG_REAL FOG_NAME(fog_linear01_depth_ortho)(FOG_REAL raw, FOG_REAL zx, FOG_REAL zy) {
  return fma(zx, raw, zy);
}

/* Reversed Z with an infinite far plane: raw = near / eye. raw == 0 gives +inf (sky), never NaN. */
FOG_FN FOG_REAL FOG_NAME(fog_eye_depth_infinite)(FOG_REAL raw, FOG_REAL near_plane) {
  return near_plane / raw;
}

/* Catlike's skybox test, the same in both Z conventions (the far plane is at Linear01 = 1). */
FOG_FN FOG_INT FOG_NAME(fog_is_sky)(FOG_REAL linear01) { return linear01 > (FOG_REAL)0.9999f; }

/* Depth-based view distance: Linear01Depth * far - near (Unity's fog coordinate). */
FOG_FN FOG_REAL FOG_NAME(fog_depth_distance)(FOG_REAL linear01, FOG_REAL near_plane,
                                             FOG_REAL far_plane) {
  return fma(linear01, far_plane, -near_plane);
}

FOG_FN FOG_REAL FOG_NAME(fog_saturate)(FOG_REAL f) {
  return fmin(fmax(f, (FOG_REAL)0), (FOG_REAL)1);
}

/* Linear: f = (end - d) / (end - start), inv_range = 1 / (end - start) > 0. Subtracting first
 * keeps f exact near d == end, where Unity's d * (-inv) + end * inv cancels. */
FOG_FN FOG_REAL FOG_NAME(fog_factor_linear)(FOG_REAL d, FOG_REAL end, FOG_REAL inv_range) {
  return FOG_NAME(fog_saturate)((end - d) * inv_range);
}

/* Linear with start == end: a hard step, 1 before start, 0 from start on. */
FOG_FN FOG_REAL FOG_NAME(fog_factor_step)(FOG_REAL d, FOG_REAL start) {
  return d < start ? (FOG_REAL)1 : (FOG_REAL)0;
}

/* 2^r for |r| <= 1/2 (a rounding error more is fine): the Chebyshev fit of degree 6
 * (scripts/exp2_coefficients.py), rounded to float, with p(0) = 1 exactly. */
FOG_FN FOG_REAL FOG_NAME(fog_exp2_reduced)(FOG_REAL r) {
  FOG_REAL p = (FOG_REAL)0x1.444p-13f;
  p = fma(p, r, (FOG_REAL)0x1.5f48cp-10f);
  p = fma(p, r, (FOG_REAL)0x1.3b2a1cp-7f);
  p = fma(p, r, (FOG_REAL)0x1.c6aeccp-5f);
  p = fma(p, r, (FOG_REAL)0x1.ebfbep-3f);
  p = fma(p, r, (FOG_REAL)0x1.62e43p-1f);
  return fma(p, r, (FOG_REAL)1);
}

/* 2^min(x, 0), the fog factors' exp2: in [0, 1] for every x, so callers need no saturate.
 * Cody-Waite split x = n + r, n = ceil(x - 1/2) an integer, |r| <= 1/2, and 2^r from
 * fog_exp2_reduced. Results below 2^-126 are flushed to 0 — a denormal factor changes no color,
 * and computing one costs microcode assists on x86. Worst error over every float in [-126, 0]:
 * 0.992 ulp (full sweep; tests/exp2_test.cpp checks every 16th float). n comes from a float ->
 * int conversion, not from the add-and-subtract-1.5*2^23 trick, which fast-math reassociation
 * folds away, nor from a round-to-nearest conversion, a 20-instruction library routine in PoCL.
 * Vendor exp2 routines are library calls on CPU OpenCL devices; this is 16 vector instructions,
 * 12 with the FOG_EXP2_LDEXP hooks. Includers reach it through FOG_EXP2 (every float path; the
 * double reference keeps the C library's exp2) and define FOG_TRUNC_INT (FOG_REAL to FOG_INT
 * rounding toward zero: C's cast), FOG_TO_REAL (FOG_INT to FOG_REAL) and FOG_AS_REAL (bit cast);
 * optionally FOG_CEIL (round up, on FOG_REAL) with FOG_EXP2_LDEXP(p, n, x) (p * 2^n where
 * x >= -126, else 0), which give the same bits. */
FOG_FN FOG_REAL FOG_NAME(fog_exp2_poly)(FOG_REAL x) {
  /* min(x, 0) by compare-and-select in minps operand order (one instruction on x86; x is never
   * NaN here). */
  FOG_REAL xc = (FOG_REAL)0 < x ? (FOG_REAL)0 : x;
#ifdef FOG_EXP2_LDEXP
  /* n stays a real and scales p in one instruction whose zero mask is the flush; lanes below
   * -126 are discarded by that mask, so they need no clamp. */
  FOG_REAL n = FOG_CEIL(xc - (FOG_REAL)0.5f);
  return FOG_EXP2_LDEXP(FOG_NAME(fog_exp2_reduced)(xc - n), n, x);
#else
  xc = (FOG_REAL)-126 > xc ? (FOG_REAL)-126 : xc;
  /* n = ceil(xc - 1/2) by truncation (xc - 1/2 < 0), one conversion instruction; the rounding
   * of xc - 1/2 can put r a rounding error past +-1/2, where the fit still holds. */
  FOG_INT n = FOG_TRUNC_INT(xc - (FOG_REAL)0.5f);
  FOG_REAL p = FOG_NAME(fog_exp2_reduced)(xc - FOG_TO_REAL(n));
  FOG_REAL scale = FOG_AS_REAL((n + 127) << 23); /* 2^n, n in [-126, 0] */
  return x < (FOG_REAL)-126 ? (FOG_REAL)0 : p * scale;
#endif
}

/* Exp: f = exp2(-d * density / ln 2) = e^(-density d); k = density * log2(e). */
FOG_FN FOG_REAL FOG_NAME(fog_factor_exp)(FOG_REAL d, FOG_REAL k) {
  return FOG_EXP2(d * -k); /* in [0, 1]: no saturate; -(d * k) with the sign on the constant */
}

/* Exp2: f = exp2(-(d * density / sqrt(ln 2))^2) = e^(-(density d)^2); k = density / sqrt(ln 2).
 * q = d, or d^2 where `squared`. (d k)^2 and (q k) k grow monotonically to +inf and
 * exp2(-inf) = 0: no NaN; q = d^2 itself overflows only beyond d = 1.8e19. */
FOG_FN FOG_REAL FOG_NAME(fog_factor_exp2)(FOG_REAL q, FOG_REAL k, int squared) {
  if (squared) return FOG_EXP2((q * k) * -k);
  FOG_REAL t = q * k;
  return FOG_EXP2(fma(-t, t, (FOG_REAL)0)); /* -(t * t) in one fused negative multiply */
}

/* Linear depth clamped as raw depth's clamp to [0, 1] clamps eye depth: into [lo, hi] (eye depth:
 * [near, far]; radial distance: the same along the pixel's ray). NaN, <= 0 (nothing written) and
 * from 0.9999 hi on (the raw path's sky test; +inf, and every value of an infinite far plane's
 * hi = +inf) are sky, at hi. */
FOG_FN FOG_REAL FOG_NAME(fog_clamp_linear_depth)(FOG_REAL value, FOG_REAL lo, FOG_REAL hi, FOG_INT* sky) {
  FOG_INT none = FOG_IS_NAN(value) | (value <= (FOG_REAL)0);
  FOG_REAL clamped = fmin(fmax(value, lo), hi);
  clamped = none ? hi : clamped;
  *sky = clamped >= (FOG_REAL)0.9999f * hi;
  return clamped;
}

/* The distance q of docs/DESIGN.md §2 from linear depth (FOG_DEPTH_EYE: eye depth along the view
 * axis; FOG_DEPTH_DISTANCE: radial distance from the eye), as the renderer wrote it: never through
 * raw depth, whose float holds eye depth only to about eye / near ulps (near 1e-6, eye 1000:
 * no digit left). ray = |ray1| of the pixel's ray at view z = 1 (the host passes unit corners),
 * or |ray1|^2 where eye depth meets `squared`; read where `distance` or for radial distance. */
FOG_FN FOG_REAL FOG_NAME(fog_view_distance_linear)(FOG_REAL value, FOG_REAL ray, int kind, int distance,
                                                   int squared, FOG_REAL near_plane, FOG_REAL far_plane,
                                                   FOG_INT* sky) {
  if (kind == FOG_DEPTH_DISTANCE) {
    if (distance) { /* the radial distance is the fog's distance: no division, no rounding */
      FOG_REAL r = FOG_NAME(fog_clamp_linear_depth)(value, near_plane * ray, far_plane * ray, sky);
      return squared ? r * r : r;
    }
    return FOG_NAME(fog_clamp_linear_depth)(value / ray, near_plane, far_plane, sky) - near_plane;
  }
  FOG_REAL e = FOG_NAME(fog_clamp_linear_depth)(value, near_plane, far_plane, sky);
  if (distance) return squared ? (e * e) * ray : e * ray;
  return e - near_plane;
}

/* Whether the ray term is |ray|^2: distance-based exp2 (FOG_SQUARED) on raw or eye depth; radial
 * distance needs |ray1| itself to bound the distance. Whether a variant reads the ray at all:
 * distance-based, or radial distance. */
#define FOG_RAY_SQUARED(mode, distance, kind) (FOG_SQUARED(mode, distance) && (kind) != FOG_DEPTH_DISTANCE)
#define FOG_NEEDS_RAY(distance, kind) ((distance) || (kind) == FOG_DEPTH_DISTANCE)

/* The distance of docs/DESIGN.md §2 from a raw depth, and whether the pixel is sky: q = d, or d^2
 * where `squared` (FOG_SQUARED: distance-based exp2). The int parameters are compile-time
 * constants in the kernel, so the branches a variant does not use fold away. ray = fog_ray_term
 * (|ray(u, v)|, or its square) is read only when distance-based (perspective only: with parallel
 * orthographic rays the host folds distance into depth). */
FOG_FN FOG_REAL FOG_NAME(fog_view_distance)(FOG_REAL raw, FOG_REAL ray, int kind, int distance,
                                            int reversed_z, int projection, int squared,
                                            FOG_REAL zx, FOG_REAL zy, FOG_REAL near_plane,
                                            FOG_REAL far_plane, FOG_INT* sky) {
  if (kind != FOG_DEPTH_RAW)
    return FOG_NAME(fog_view_distance_linear)(raw, ray, kind, distance, squared, near_plane, far_plane, sky);
  FOG_REAL depth = FOG_NAME(fog_sanitize_depth)(raw, reversed_z);
  /* scale * |ray| is the distance-based d; the depth-based d has no ray. */
  FOG_REAL scale, d;
  if (projection == FOG_PROJECTION_INFINITE_FAR) {
    /* Depth 0 is infinitely far: sky, decided on the raw value before any arithmetic. */
    *sky = depth == (FOG_REAL)0;
    scale = FOG_NAME(fog_eye_depth_infinite)(depth, near_plane);
    d = scale - near_plane;
  } else {
    scale = projection == FOG_PROJECTION_ORTHOGRAPHIC
                ? FOG_NAME(fog_linear01_depth_ortho)(depth, zx, zy)
                : FOG_NAME(fog_linear01_depth)(depth, zx, zy, reversed_z);
    *sky = FOG_NAME(fog_is_sky)(scale);
    d = FOG_NAME(fog_depth_distance)(scale, near_plane, far_plane);
  }
  if (distance) return squared ? (scale * scale) * ray : scale * ray;
  return d;
}

/* The fog factor f at view distance q (fog_view_distance: d, or d^2 where squared; it also says
 * whether the pixel is sky). k_a, k_b: linear (end, 1 / (end - start)); step (start); exp and exp2 (k,
 * density). sky_infinite (FogSettings::sky, implies fog_skybox): the sky is infinitely far, f = 0
 * in every mode (a renderer's mist), instead of Unity's sky at the far plane. */
FOG_FN FOG_REAL FOG_NAME(fog_factor_at)(FOG_REAL q, FOG_INT sky, int mode, int squared,
                                        int fog_skybox, int sky_infinite, FOG_REAL k_a, FOG_REAL k_b) {
  FOG_REAL f = mode == FOG_MODE_LINEAR ? FOG_NAME(fog_factor_linear)(q, k_a, k_b)
             : mode == FOG_MODE_STEP   ? FOG_NAME(fog_factor_step)(q, k_a)
             : mode == FOG_MODE_EXP    ? FOG_NAME(fog_factor_exp)(q, k_a)
                                       : FOG_NAME(fog_factor_exp2)(q, k_a, squared);
  if (sky_infinite) return sky ? (FOG_REAL)0 : f;
  return fog_skybox ? f : (sky ? (FOG_REAL)1 : f);
}

/* The fog amount 1 - f at view distance q (as fog_factor_at), without the cancellation of
 * computing 1 - f when f is close to 1: exp: -expm1(-density d); exp2: -expm1(-(density d)^2).
 * Linear and step: 1 - f (exact where it matters: f is then far from 1 or exactly 0 / 1).
 * Reported by the scalar path (FogResult). */
FOG_FN FOG_REAL FOG_NAME(fog_amount_at)(FOG_REAL q, FOG_INT sky, int mode, int squared,
                                        int fog_skybox, int sky_infinite, FOG_REAL k_a, FOG_REAL k_b) {
  FOG_REAL x = q * k_b; /* exp / exp2: density * d, or density * d^2 where squared */
  FOG_REAL a = mode == FOG_MODE_LINEAR ? (FOG_REAL)1 - FOG_NAME(fog_factor_linear)(q, k_a, k_b)
             : mode == FOG_MODE_STEP   ? (FOG_REAL)1 - FOG_NAME(fog_factor_step)(q, k_a)
             : mode == FOG_MODE_EXP    ? -expm1(-x)
                                       : -expm1(-(squared ? x * k_b : x * x));
  if (sky_infinite) return sky ? (FOG_REAL)1 : FOG_NAME(fog_saturate)(a);
  return fog_skybox ? FOG_NAME(fog_saturate)(a) : (sky ? (FOG_REAL)0 : FOG_NAME(fog_saturate)(a));
}

/* The fog factor f of a pixel from its depth sample (raw or linear, `kind`): the whole chain of
 * docs/DESIGN.md §2. */
FOG_FN FOG_REAL FOG_NAME(fog_factor)(FOG_REAL raw, FOG_REAL ray, int kind, int mode, int distance,
                                     int fog_skybox, int sky_infinite, int reversed_z, int projection,
                                     FOG_REAL zx, FOG_REAL zy, FOG_REAL near_plane, FOG_REAL far_plane,
                                     FOG_REAL k_a, FOG_REAL k_b) {
  FOG_INT sky;
  int squared = FOG_SQUARED(mode, distance);
  FOG_REAL q = FOG_NAME(fog_view_distance)(raw, ray, kind, distance, reversed_z, projection, squared,
                                           zx, zy, near_plane, far_plane, &sky);
  return FOG_NAME(fog_factor_at)(q, sky, mode, squared, fog_skybox, sky_infinite, k_a, k_b);
}

/* Blend one channel: fogColor + f * (c - fogColor). f == 1 returns c untouched (bit-exact, NaN
 * and Inf included) and f == 0 returns exactly the fog color (a hidden NaN never leaks).
 * fog_blend_mix is the formula alone, for callers that know 0 < f < 1. */
FOG_FN FOG_REAL FOG_NAME(fog_blend_mix)(FOG_REAL c, FOG_REAL fog_color, FOG_REAL f) {
  return fma(f, c - fog_color, fog_color);
}
FOG_FN FOG_REAL FOG_NAME(fog_blend)(FOG_REAL c, FOG_REAL fog_color, FOG_REAL f) {
  return f == (FOG_REAL)1 ? c
       : (f == (FOG_REAL)0 ? fog_color : FOG_NAME(fog_blend_mix)(c, fog_color, f));
}

/* End of this instance: the includer's instance macros go, so the next instance can define its
 * own (FOG_EXP2 stays: it is written in terms of FOG_NAME). */
#undef FOG_REAL
#undef FOG_INT
#undef FOG_AS_UINT
#undef FOG_TRUNC_INT
#undef FOG_TO_REAL
#undef FOG_AS_REAL
#undef FOG_CEIL
#undef FOG_EXP2_LDEXP
#undef FOG_NAME
#undef FOG_LANES16
