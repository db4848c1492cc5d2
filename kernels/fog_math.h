/* fog_math.h — the per-pixel formulas of docs/DESIGN.md §2, written once and compiled three ways:
 *   - OpenCL C on one pixel:       FOG_REAL float,   FOG_INT int,   FOG_NAME(f) f
 *   - OpenCL C on 16 pixels:       FOG_REAL float16, FOG_INT int16, FOG_NAME(f) f##_v
 *     (vector lanes are independent pixels; every operation is lane-wise IEEE, so a lane rounds
 *     exactly like the scalar version);
 *   - C++ (src/pass/scalar_fog.cpp): FOG_FN makes each function a template on FOG_REAL, so the
 *     same text runs in float for the baseline and in double for the reference.
 * In OpenCL C this file defines the instance's macros itself (below): the one-pixel instance, or
 * the 16-pixel one when the includer defines FOG_LANES16; the includer defines FOG_EXP2 and may
 * define the optional hooks FOG_CEIL, FOG_FLOOR, FOG_SCALE2 (p 2^n, one rounding) and
 * FOG_EXP2_LDEXP. In C++ the includer defines FOG_INT, FOG_NAME, FOG_TRUNC_INT, FOG_TO_REAL and
 * FOG_AS_REAL. This file has no include guard on purpose
 * and undefines the instance macros (not FOG_EXP2) at its end. Only operations that exist in both languages
 * appear: + - * /, fma, expm1, sqrt, fmin, fmax, integer + and <<, a float -> int conversion, and
 * ?: (a per-lane select on vectors in OpenCL C), besides the optional hooks.
 * Sources: Unity's UnityCG.cginc (Linear01Depth, UNITY_CALC_FOG_FACTOR_RAW) and Catlike Coding,
 * "Rendering 14: Fog" (deferred fog, depth vs distance, the skybox test). */

#ifndef FOG_FN
#ifdef __OPENCL_C_VERSION__
#define FOG_FN static inline
/* Height fog's functions are always inlined: PoCL inlines nothing else after clang's -O2, and a
 * call left in the work-item loop keeps its vectoriser from spreading the loop over SIMD lanes. */
#define FOG_FN_INLINE static inline __attribute__((always_inline))
#else
#define FOG_FN template <typename FOG_REAL> inline
#define FOG_FN_INLINE template <typename FOG_REAL> [[gnu::always_inline]] inline
#endif
#endif

/* The OpenCL C instances: lanes are independent pixels, names of the 16-pixel one end in _v. */
#if defined(__OPENCL_C_VERSION__) && !defined(FOG_REAL)
#ifdef FOG_LANES16
#define FOG_REAL float16
#define FOG_INT int16
#define FOG_AS_UINT as_uint16
#define FOG_AS_INT as_int16
#define FOG_TRUNC_INT convert_int16
#define FOG_TO_REAL convert_float16
#define FOG_AS_REAL as_float16
#define FOG_NAME(name) name##_v
#else
#define FOG_REAL float
#define FOG_INT int
#define FOG_AS_UINT as_uint
#define FOG_AS_INT as_int
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
#define FOG_MODE_HEIGHT 5 /* height and atmospheric fog, docs/DESIGN.md §6 */
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

/* NaN and infinity tests that survive -cl-fast-relaxed-math (which may fold x != x, or a
 * comparison with INFINITY, away): the bit pattern.
 * The includer of an OpenCL instance defines FOG_AS_UINT (as_uint, as_uint16). */
#ifdef __OPENCL_C_VERSION__
#define FOG_IS_NAN(x) ((FOG_AS_UINT(x) & 0x7fffffffu) > 0x7f800000u)
#define FOG_IS_INF(x) ((FOG_AS_UINT(x) & 0x7fffffffu) == 0x7f800000u)
#else
#define FOG_IS_NAN(x) isnan(x)
#define FOG_IS_INF(x) isinf(x)
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

/* ---- Height and atmospheric fog (docs/DESIGN.md §6: Unreal's exponential height fog, Filament's
 * and Godot's height falloff, Bevy's per-channel extinction and in-scattering, a sun lobe) ----
 * In closed form, without a branch on the value and without an epsilon. Written for the
 * one-pixel instances (OpenCL C float, C++ float and double) and the 16-pixel one alike: every choice
 * on a pixel's value is a select. */
/* What a height-fog variant uses (FOG_HEIGHT_* build options; HeightCoefficients on the host):
 * a bit mask that is a compile-time constant in the kernel, so unused parts fold away. */
#ifndef FOG_HF_FALLOFF
#define FOG_HF_FALLOFF 1       /* k != 0 (else H = L: no exp at all) */
#define FOG_HF_RGB 2           /* per-channel coefficients (else one channel serves three) */
#define FOG_HF_START 4         /* s_start > 0 */
#define FOG_HF_CUTOFF 8        /* s_cut finite */
#define FOG_HF_MAX_OPACITY 16  /* m < 1 */
#define FOG_HF_SUN 32          /* the sun lobe */
#define FOG_HF_SUN_START 64    /* the lobe's start s_sun > s_start */
#define FOG_HF_SKYBOX 128      /* the sky is fogged, as an infinite ray (or up to s_cut) */
#define FOG_HF_SAME_IN 256     /* beta_in == beta_ext: T and J from one exponential */
/* Per-frame constants, in this order (fog_height_constants on the host). */
#define FOG_HP_K 0           /* falloff k [1/world unit] */
#define FOG_HP_START 1       /* s_start */
#define FOG_HP_CUTOFF 2      /* s_cut */
#define FOG_HP_MAX 3         /* m */
#define FOG_HP_MIN_T 4       /* 1 - m */
#define FOG_HP_SUN_EXP 5     /* e */
#define FOG_HP_SUN_START 6   /* s_sun */
#define FOG_HP_EXT 7         /* beta_ext R, G, B */
#define FOG_HP_IN 10         /* beta_in R, G, B */
#define FOG_HP_FOG 13        /* fog color F */
#define FOG_HP_SUN 16        /* sun color S */
#define FOG_HP_COUNT 19
/* The FOG_HP_* block's element type: float in OpenCL C (both instances), the path's real in C++. */
#ifdef __OPENCL_C_VERSION__
#define FOG_HP_T float
#else
#define FOG_HP_T FOG_REAL
#endif
#endif

/* exp, expm1 and log1p of height fog, as branch-free polynomials for every float path (inlined, so
 * that PoCL's work-group vectoriser spreads them over SIMD lanes: a library call blocks it, and it
 * costs 20-30x the pass's time at 1080p), the C library's for the double reference. The includer
 * reaches them through FOG_EXP, FOG_EXPM1 and FOG_LOG1P (OpenCL: these, by default) and defines
 * FOG_AS_INT (bit cast to FOG_INT) besides fog_exp2_poly's macros. */
/* e^r - 1 for |r| <= ln2/2 (+ a rounding): Taylor to r^8 / 8!, truncation 5e-10 relative. */
FOG_FN_INLINE FOG_REAL FOG_NAME(fog_expm1_reduced)(FOG_REAL r) {
  FOG_REAL p = (FOG_REAL)0x1.a01a02p-16f;
  p = fma(p, r, (FOG_REAL)0x1.a01a02p-13f);
  p = fma(p, r, (FOG_REAL)0x1.6c16c2p-10f);
  p = fma(p, r, (FOG_REAL)0x1.111112p-7f);
  p = fma(p, r, (FOG_REAL)0x1.555556p-5f);
  p = fma(p, r, (FOG_REAL)0x1.555556p-3f);
  p = fma(p, r, (FOG_REAL)0.5f);
  return fma(r * r, p, r);
}
/* floor, or the includer's FOG_FLOOR giving the same bits (PoCL's floor is a 12-instruction
 * routine; on AVX-512 one vrndscaleps). */
#ifndef FOG_FLOOR
#define FOG_FLOOR floor
#endif
/* x = n ln2 + r, |r| <= ln2/2: n = floor(x log2(e) + 1/2), r with ln2 in two parts (Cody-Waite). */
FOG_FN_INLINE FOG_REAL FOG_NAME(fog_ln2_reduce)(FOG_REAL x, FOG_REAL* n) {
  *n = FOG_FLOOR(fma(x, (FOG_REAL)0x1.715476p+0f, (FOG_REAL)0.5f));
  return fma(-*n, (FOG_REAL)0x1.7f7d1cp-20f, fma(-*n, (FOG_REAL)0x1.62e4p-1f, x));
}
/* 2^n for an integral n in [-126, 127]. */
FOG_FN_INLINE FOG_REAL FOG_NAME(fog_pow2i)(FOG_REAL n) { return FOG_AS_REAL((FOG_TRUNC_INT(n) + 127) << 23); }
/* e^x for every x: within about 1 ulp; +inf above 88.72, 0 below -103.97 (no denormal results
 * below 2^-126 but those 2^n (1 + em) keeps). */
FOG_FN_INLINE FOG_REAL FOG_NAME(fog_exp_poly)(FOG_REAL x) {
  FOG_REAL xc = fmin(fmax(x, (FOG_REAL)-104.0f), (FOG_REAL)89.0f), n;
  FOG_REAL em = FOG_NAME(fog_expm1_reduced)(FOG_NAME(fog_ln2_reduce)(xc, &n));
#ifdef FOG_SCALE2
  FOG_REAL e = FOG_SCALE2((FOG_REAL)1 + em, n);
#else
  /* 2^n in two factors: n in [-150, 129] has no single float scale. The first product is exact
   * (normal), so the result is rounded once, as FOG_SCALE2's is. */
  FOG_REAL n1 = FOG_FLOOR(n * (FOG_REAL)0.5f);
  FOG_REAL e = ((FOG_REAL)1 + em) * FOG_NAME(fog_pow2i)(n1) * FOG_NAME(fog_pow2i)(n - n1);
#endif
  return x > (FOG_REAL)0x1.62e42ep+6f ? (FOG_REAL)INFINITY : (x < (FOG_REAL)-103.972f ? (FOG_REAL)0 : e);
}
/* log(1 + y) for -1 < y <= 0 (the sun lobe's log(cos θ) from y = -(1 - cos θ)): u = 1 + y,
 * log1p(y) = log(u) y / (u - 1) (exact in u - 1, Goldberg's correction of u's rounding), log(u) from
 * u = m 2^k, m in [sqrt(1/2), sqrt(2)), log(m) = 2 atanh(s), s = (m - 1) / (m + 1), to s^9. */
FOG_FN_INLINE FOG_REAL FOG_NAME(fog_log1p_neg_poly)(FOG_REAL y) {
  FOG_REAL u = (FOG_REAL)1 + y;
  FOG_INT bits = FOG_AS_INT(u);
  FOG_REAL k = FOG_TO_REAL(((bits >> 23) & 0xff) - 127);
  FOG_REAL m = FOG_AS_REAL((bits & 0x7fffff) | 0x3f800000);
  FOG_INT big = m > (FOG_REAL)0x1.6a09e6p+0f;
  m = big ? m * (FOG_REAL)0.5f : m;
  k = big ? k + (FOG_REAL)1 : k;
  FOG_REAL f = m - (FOG_REAL)1;
  FOG_REAL t = f / ((FOG_REAL)2 + f), z = t * t;
  FOG_REAL r = fma(z, (FOG_REAL)0x1.745d18p-3f, (FOG_REAL)0x1.c71c72p-3f);
  r = fma(r, z, (FOG_REAL)0x1.24924ap-2f);
  r = fma(r, z, (FOG_REAL)0x1.99999ap-2f);
  r = fma(r, z, (FOG_REAL)0x1.555556p-1f);
  FOG_REAL log_m = fma(t * z, r, t + t);
  FOG_REAL log_u = fma(k, (FOG_REAL)0x1.62e4p-1f, fma(k, (FOG_REAL)0x1.7f7d1cp-20f, log_m));
  return u == (FOG_REAL)1 ? y : log_u * (y / (u - (FOG_REAL)1));
}
/* e^x and e^x - 1 of one x <= 0 from one reduction (T and J where beta_in == beta_ext): e^x is
 * 2^n (1 + em), exactly what fog_exp_poly gives but below 2^-126 (0 here). e^x - 1: relative
 * error about 1 ulp, exactly -1 from x = -30 on (the true value rounds to it from -17.4; s - 1 is
 * -1 once s < 2^-25); NaN never comes in. Returns e^x, writes e^x - 1. */
FOG_FN_INLINE FOG_REAL FOG_NAME(fog_exp_expm1_neg_poly)(FOG_REAL x, FOG_REAL* expm1_x) {
  FOG_REAL n;
  /* Held to [-87, 0] (the same bits there): a positive x, whose result a caller's select drops,
   * would otherwise ask fog_pow2i for 2^n beyond float's exponent (and the C++ path for an int
   * conversion out of range). */
  FOG_REAL em = FOG_NAME(fog_expm1_reduced)(
      FOG_NAME(fog_ln2_reduce)(fmin(fmax(x, (FOG_REAL)-87.0f), (FOG_REAL)0), &n));
  FOG_REAL s = FOG_NAME(fog_pow2i)(n);
  *expm1_x = fma(s, em, s - (FOG_REAL)1); /* n = 0: em itself */
  return x < (FOG_REAL)-87.0f ? (FOG_REAL)0 : fma(s, em, s);
}
/* e^x - 1 for x <= 0 (height fog's only arguments): fog_exp_expm1_neg_poly's, whose e^x then
 * folds away. */
FOG_FN_INLINE FOG_REAL FOG_NAME(fog_expm1_neg_poly)(FOG_REAL x) {
  FOG_REAL expm1_x;
  FOG_NAME(fog_exp_expm1_neg_poly)(x, &expm1_x);
  return expm1_x;
}
#if defined(__OPENCL_C_VERSION__) && defined(FOG_DEVICE_EXP)
/* e^x for x <= 0 whose result is budgeted absolutely (T, the lobe), from the device's exp2: the
 * rounding of x log2(e) moves e^x by e^x |x| 2^-24 at most, under 2.2e-8 (e^x |x| <= 1/e). */
FOG_FN_INLINE FOG_REAL FOG_NAME(fog_exp_neg_device)(FOG_REAL x) { return exp2(x * (FOG_REAL)0x1.715476p+0f); }
/* fog_exp_expm1_neg_poly's contract from the device: e^x, 0 below -87, and e^x - 1 as T - 1, whose
 * absolute error (T's plus half an ulp of 1) is what §6.3 budgets. */
FOG_FN_INLINE FOG_REAL FOG_NAME(fog_exp_expm1_device)(FOG_REAL x, FOG_REAL* expm1_x) {
  FOG_REAL t = x < (FOG_REAL)-87.0f ? (FOG_REAL)0 : FOG_NAME(fog_exp_neg_device)(x);
  *expm1_x = t - (FOG_REAL)1;
  return t;
}
#endif
#ifdef __OPENCL_C_VERSION__
#ifndef FOG_EXP
#ifdef FOG_DEVICE_EXP
/* GPUs (FOG_DEVICE_EXP): their exp and exp2 take a few instructions (NVIDIA: 2-12 against the
 * polynomial's ~40) within the OpenCL spec's 3 ulp. T, J and the lobe are budgeted absolutely
 * (docs/DESIGN.md §6.3: 4e-6), so 3 ulp of them, or J as T - 1, cost nothing of it; H's
 * e^(-k h*) is relative: exp itself, 3 ulp against the 4e-6. G's expm1 and the lobe's log1p keep
 * the polynomials: there the relative digits of small arguments matter. */
#define FOG_EXP_EXPM1 FOG_NAME(fog_exp_expm1_device)
#define FOG_EXP exp
#define FOG_EXP_NEG FOG_NAME(fog_exp_neg_device)
#else
#define FOG_EXP_EXPM1 FOG_NAME(fog_exp_expm1_neg_poly)
#define FOG_EXP FOG_NAME(fog_exp_poly)
#define FOG_EXP_NEG FOG_NAME(fog_exp_poly)
#endif
#define FOG_EXPM1 FOG_NAME(fog_expm1_neg_poly)
#define FOG_LOG1P FOG_NAME(fog_log1p_neg_poly)
#endif
#endif

/* H = integral over [s0, s1] of e^(-k (h(s) - b)) ds along a ray whose height above the base is
 * d0 + s * wy (wy = ω.y, d0 = origin height - b). H = L e^(-k (h* - b)) G(|x|), x = k wy L (the
 * height change times k, from the direction, never a difference of heights, which cancels), h*
 * the end where the integrand is largest: only that one is exponentiated, so nothing overflows
 * that the true value does not. falloff == 0 (k = 0): H = L. sky_infinite (a fogged sky without a
 * cut-off: s1 = +inf, whatever s1 says): H = e^(-k (h0 - b)) / (k wy) where k wy > 0, else +inf
 * (k = 0 included). */
FOG_FN_INLINE FOG_REAL FOG_NAME(fog_height_length)(FOG_REAL s0, FOG_REAL s1, FOG_REAL wy, FOG_REAL d0, FOG_REAL k,
                                            int falloff, FOG_INT sky_infinite) {
  FOG_REAL L = s1 - s0;
  /* k = 0: the integrand is 1, H = L; but the sky's ray is infinite (its s1 is only the far
   * plane's distance, which a start or sun start may pass): H = +inf, so that T = 0 and J = 1
   * where beta > 0, T = 1 and J = 0 where beta = 0 (fog_height_depth's 0 inf = 0). */
  if (!falloff) return sky_infinite ? (FOG_REAL)INFINITY : L;
  /* A surface past float's range (s1 = +inf: an infinite far plane's raw depth below near /
   * FLT_MAX) is as far as the sky: L e G would be inf 0. */
  sky_infinite = sky_infinite | FOG_IS_INF(s1);
  FOG_REAL kwy = k * wy;
  FOG_REAL x = kwy * L;
  FOG_REAL e0 = fma(s0, wy, d0); /* h0 - b */
  FOG_REAL e1 = fma(s1, wy, d0); /* h1 - b */
  /* The infinite ray rises (or is +inf) from h0: its exponential is e0's too, so the sky and the
   * surface share one exponential and one division. */
  FOG_REAL top = (sky_infinite | (x >= (FOG_REAL)0)) ? e0 : e1;
  FOG_REAL e = FOG_EXP(-k * top);
  /* G(a) = (1 - e^-a) / a for a = |x| >= 0, G(0) = 1 by a select: expm1 keeps every digit of tiny
   * a, so no series branch is needed (Unreal's switches to a Taylor series below |x| = 0.01). */
  FOG_REAL a = fabs(x);
  FOG_REAL q = (sky_infinite ? e : -FOG_EXPM1(-a)) / (sky_infinite ? kwy : a);
  /* G >= FLT_MIN: G = 1 / a underflows only where a = k wy L > 2^126, where e may be +inf too. */
  FOG_REAL h = L * e * (a == (FOG_REAL)0 ? (FOG_REAL)1 : fmax(q, (FOG_REAL)0x1p-126f));
  FOG_REAL h_inf = kwy > (FOG_REAL)0 ? q : (FOG_REAL)INFINITY;
  return sky_infinite ? h_inf : h;
}

/* The optical depth beta * H with 0 * inf = 0: a zero coefficient is no fog in its channel. */
FOG_FN_INLINE FOG_REAL FOG_NAME(fog_height_depth)(FOG_REAL beta, FOG_REAL h) {
  return beta == (FOG_REAL)0 ? (FOG_REAL)0 : beta * h;
}

/* The sun lobe max(cos θ, 0)^e from q = 1 - cos θ = |ω - ℓ|^2 / 2 (ω, ℓ unit vectors): the
 * difference keeps the digits of small angles that a rounded cosine loses (e = 1000 near the
 * peak), and exp(e log1p(-q)) those of the power. 0 where cos θ <= 0 (q >= 1). */
FOG_FN_INLINE FOG_REAL FOG_NAME(fog_sun_lobe)(FOG_REAL q, FOG_REAL e) {
  return q < (FOG_REAL)1 ? FOG_EXP_NEG(e * FOG_LOG1P(-q)) : (FOG_REAL)0;
}

/* 1 - cos(ω, ℓ) = |ω - ℓ|^2 / 2 for unit ω = (wx, wy, wz) and ℓ. */
FOG_FN_INLINE FOG_REAL FOG_NAME(fog_sun_q)(FOG_REAL wx, FOG_REAL wy, FOG_REAL wz, FOG_REAL lx, FOG_REAL ly, FOG_REAL lz) {
  FOG_REAL dx = wx - lx, dy = wy - ly, dz = wz - lz;
  return fma(dx, dx, fma(dy, dy, dz * dz)) * (FOG_REAL)0.5f;
}

/* One channel's output color * T + F * J + sun (sun = S λ J_sun). T == 0 contributes exactly 0,
 * whatever the color (a hidden NaN or Inf never leaks). */
FOG_FN_INLINE FOG_REAL FOG_NAME(fog_height_blend)(FOG_REAL c, FOG_REAL t, FOG_REAL f, FOG_REAL j, FOG_REAL sun) {
  FOG_REAL added = fma(f, j, sun);
  return t == (FOG_REAL)0 ? added : fma(c, t, added);
}

/* Channel c's transmittance T, in-scattered fraction J and the sun's J_sun (docs/DESIGN.md §6.2)
 * from H and H_sun, capped by the maximum opacity where the variant has one. */
FOG_FN_INLINE void FOG_NAME(fog_height_tj)(FOG_REAL h, FOG_REAL h_sun, const FOG_HP_T* p, int c, int features,
                                           FOG_REAL* t, FOG_REAL* j, FOG_REAL* j_sun) {
  if (features & FOG_HF_SAME_IN) {
    *t = FOG_EXP_EXPM1(-FOG_NAME(fog_height_depth)((FOG_REAL)p[FOG_HP_EXT + c], h), j);
    *j = -*j;
  } else {
    *t = FOG_EXP_NEG(-FOG_NAME(fog_height_depth)((FOG_REAL)p[FOG_HP_EXT + c], h));
    *j = -FOG_EXPM1(-FOG_NAME(fog_height_depth)((FOG_REAL)p[FOG_HP_IN + c], h));
  }
  *j_sun = (features & FOG_HF_SUN_START) ? -FOG_EXPM1(-FOG_NAME(fog_height_depth)((FOG_REAL)p[FOG_HP_IN + c], h_sun))
                                         : *j;
  if (features & FOG_HF_MAX_OPACITY) {
    *t = fmax(*t, (FOG_REAL)p[FOG_HP_MIN_T]);
    *j = fmin(*j, (FOG_REAL)p[FOG_HP_MAX]);
    *j_sun = fmin(*j_sun, (FOG_REAL)p[FOG_HP_MAX]);
  }
}

/* Channel c of a pixel's output: its color where the pixel is not fogged, bit for bit. */
FOG_FN_INLINE FOG_REAL FOG_NAME(fog_height_out)(FOG_REAL color, FOG_REAL t, FOG_REAL j, FOG_REAL j_sun,
                                                FOG_REAL lobe, FOG_INT fogged, const FOG_HP_T* p, int c,
                                                int features) {
  FOG_REAL sun = (features & FOG_HF_SUN) ? (FOG_REAL)p[FOG_HP_SUN + c] * lobe * j_sun : (FOG_REAL)0;
  FOG_REAL fogged_c = FOG_NAME(fog_height_blend)(color, t, (FOG_REAL)p[FOG_HP_FOG + c], j, sun);
  return fogged ? fogged_c : color;
}

/* The height fog of one pixel (docs/DESIGN.md §6.2) into rgb[0..2]. s_hit: distance along the ray
 * to the surface (fog_view_distance's distance-based metric), sky: the pixel is sky, wy: ω.y,
 * d0: the ray origin's height - b, q_sun: 1 - cos(ω, ℓ) (read with FOG_HF_SUN), p: FOG_HP_*
 * constants, features: FOG_HF_* bits. Returns whether the pixel is fogged; where it is not, rgb
 * is left untouched, bit for bit (sky without FOG_HF_SKYBOX, an empty segment, H = 0 and
 * H_sun = 0). Branch-free on the pixel's values (selects), so that it runs on 16 lanes too. */
FOG_FN_INLINE FOG_INT FOG_NAME(fog_height_pixel)(FOG_REAL* rgb, FOG_REAL s_hit, FOG_INT sky, FOG_REAL wy,
                                                FOG_REAL d0, FOG_REAL q_sun, const FOG_HP_T* p, int features) {
  const int falloff = (features & FOG_HF_FALLOFF) != 0;
  FOG_REAL s0 = (features & FOG_HF_START) ? (FOG_REAL)p[FOG_HP_START] : (FOG_REAL)0;
  FOG_REAL s1 = (features & FOG_HF_CUTOFF) ? fmin(s_hit, (FOG_REAL)p[FOG_HP_CUTOFF]) : s_hit;
  FOG_INT sky_infinite = 0, pass = 0;
  if (features & FOG_HF_SKYBOX) {
    /* §6.2: the sky is infinitely far in this mode, cut at s_cut where there is one. */
    if (features & FOG_HF_CUTOFF) s1 = sky ? (FOG_REAL)p[FOG_HP_CUTOFF] : s1;
    else sky_infinite = sky;
  } else {
    pass = sky;
  }
  pass = pass | (!sky_infinite & !(s1 > s0));
  FOG_REAL k = (FOG_REAL)p[FOG_HP_K];
  FOG_REAL h = FOG_NAME(fog_height_length)(s0, s1, wy, d0, k, falloff, sky_infinite);
  FOG_REAL h_sun = h, lobe = (FOG_REAL)0;
  if (features & FOG_HF_SUN) {
    lobe = FOG_NAME(fog_sun_lobe)(q_sun, (FOG_REAL)p[FOG_HP_SUN_EXP]);
    if (features & FOG_HF_SUN_START) {
      FOG_REAL s0_sun = fmax(s0, (FOG_REAL)p[FOG_HP_SUN_START]);
      h_sun = (sky_infinite | (s1 > s0_sun)) ? FOG_NAME(fog_height_length)(s0_sun, s1, wy, d0, k, falloff, sky_infinite)
                                             : (FOG_REAL)0;
    }
  }
  FOG_INT fogged = !pass & !((h == (FOG_REAL)0) & (h_sun == (FOG_REAL)0));
  /* Channel by channel in straight-line code: a loop over them kept the 16-lane instance's colors
   * in memory (PoCL left it rolled). */
  FOG_REAL t[3], j[3], j_sun[3];
  FOG_NAME(fog_height_tj)(h, h_sun, p, 0, features, &t[0], &j[0], &j_sun[0]);
  if (features & FOG_HF_RGB) {
    FOG_NAME(fog_height_tj)(h, h_sun, p, 1, features, &t[1], &j[1], &j_sun[1]);
    FOG_NAME(fog_height_tj)(h, h_sun, p, 2, features, &t[2], &j[2], &j_sun[2]);
  } else {
    t[1] = t[2] = t[0];
    j[1] = j[2] = j[0];
    j_sun[1] = j_sun[2] = j_sun[0];
  }
  rgb[0] = FOG_NAME(fog_height_out)(rgb[0], t[0], j[0], j_sun[0], lobe, fogged, p, 0, features);
  rgb[1] = FOG_NAME(fog_height_out)(rgb[1], t[1], j[1], j_sun[1], lobe, fogged, p, 1, features);
  rgb[2] = FOG_NAME(fog_height_out)(rgb[2], t[2], j[2], j_sun[2], lobe, fogged, p, 2, features);
  return fogged;
}
/* The height fog marched (docs/DESIGN.md §6.5): segment [σ_i, σ_i+1] of a ray's fog stretch, channel c.
 * h: §6.2's H over the segment (fog_height_length), h_sun: H over its part beyond s_sun, v: the
 * sun's visibility sampled in it (1 lit, 0 shadowed). Adds the segment to the extinction depth
 * β_ext·ΣH, the in-scattering depths β_in·ΣH and β_in·ΣH_sun, and the ambient and sun fractions
 * Σ e^(-β_in τ)·(1 - e^(-β_in H_i)) (the sun's times v), whose sums over the segments telescope to
 * §6.2's J and J_sun: with v = 1 everywhere the march is the closed form, whatever the segments.
 * other: the optical depth of other media in the segment (0: none), depth_other: theirs in front.
 * sun_apart == 0 (no sun start: h_sun == h in every segment, so the sun's depths are the
 * ambient's) takes the sun's exponentials from the ambient's: the same values, half the work. */
FOG_FN_INLINE void FOG_NAME(fog_height_march_segment)(FOG_REAL h, FOG_REAL h_sun, FOG_REAL v, FOG_REAL other,
                                                      FOG_REAL depth_other, const FOG_HP_T* p, int c, int sun_apart,
                                                      FOG_REAL* depth_ext, FOG_REAL* depth_in, FOG_REAL* depth_sun,
                                                      FOG_REAL* ambient, FOG_REAL* sun) {
  FOG_REAL b_in = (FOG_REAL)p[FOG_HP_IN + c];
  FOG_REAL d_in = FOG_NAME(fog_height_depth)(b_in, h), d_sun = d_in;
  /* Other media in the segment (fog volumes, optical depth `other` > 0, never on an infinite tail)
   * take their share of its scattering: the fog's is d / (d + other) of 1 - e^(-(d + other)). */
  FOG_REAL share = other > (FOG_REAL)0 ? d_in / (d_in + other) : (FOG_REAL)1;
  FOG_REAL front = FOG_EXP_NEG(-(*depth_in + depth_other)), scattered = -FOG_EXPM1(-(d_in + other));
  FOG_REAL share_sun = share, front_sun = front, scattered_sun = scattered;
  if (sun_apart) {
    d_sun = FOG_NAME(fog_height_depth)(b_in, h_sun);
    share_sun = other > (FOG_REAL)0 ? d_sun / (d_sun + other) : (FOG_REAL)1;
    front_sun = FOG_EXP_NEG(-(*depth_sun + depth_other));
    scattered_sun = -FOG_EXPM1(-(d_sun + other));
  }
  *ambient = fma(front * share, scattered, *ambient);
  *sun = fma(v * front_sun * share_sun, scattered_sun, *sun);
  *depth_in = *depth_in + d_in;
  *depth_sun = *depth_sun + d_sun;
  *depth_ext = *depth_ext + FOG_NAME(fog_height_depth)((FOG_REAL)p[FOG_HP_EXT + c], h);
}

/* Channel c of a marched pixel: color·T + F·ambient + S·λ·sun with T = e^(-depth_ext), as
 * fog_height_out blends the closed form's (lobe: λ, read with FOG_HF_SUN). */
FOG_FN_INLINE FOG_REAL FOG_NAME(fog_height_march_out)(FOG_REAL color, FOG_REAL depth_ext, FOG_REAL ambient,
                                                      FOG_REAL sun, FOG_REAL lobe, const FOG_HP_T* p, int c,
                                                      int features) {
  FOG_REAL s = (features & FOG_HF_SUN) ? (FOG_REAL)p[FOG_HP_SUN + c] * lobe * sun : (FOG_REAL)0;
  return FOG_NAME(fog_height_blend)(color, FOG_EXP_NEG(-depth_ext), (FOG_REAL)p[FOG_HP_FOG + c], ambient, s);
}

/* Height fog's geometry of a pixel (docs/DESIGN.md §6.1), in view space: no rotation per pixel.
 * (cx, cy, cz): the pixel's corner ray (fog_bilerp of fog_ray_corners: at the far plane for raw
 * depth, at view z = 1 for linear depth and the infinite far plane; orthographic: the far-plane
 * rectangle), (ux, uy, uz): world +y in view space, (lx, ly, lz): the light in view space (read
 * with `sun`), d0: eye.y - b. Returns s_hit, the distance along the ray from the eye (§2's
 * distance-based metric; orthographic: eye depth from the view plane) and writes the sky flag,
 * ω.y, the ray origin's height - b and 1 - cos(ω, ℓ). */
FOG_FN_INLINE FOG_REAL FOG_NAME(fog_height_geometry)(FOG_REAL raw, FOG_REAL cx, FOG_REAL cy, FOG_REAL cz, int kind,
                                              int reversed_z, int projection, FOG_REAL zx, FOG_REAL zy,
                                              FOG_REAL near_plane, FOG_REAL far_plane, FOG_REAL ux, FOG_REAL uy,
                                              FOG_REAL uz, FOG_REAL lx, FOG_REAL ly, FOG_REAL lz, int sun,
                                              FOG_REAL d0, FOG_INT* sky, FOG_REAL* wy, FOG_REAL* d0_pixel,
                                              FOG_REAL* q_sun) {
  if (projection == FOG_PROJECTION_ORTHOGRAPHIC) {
    /* ω = forward (view +z); the ray starts on the view plane at (cx, cy, 0). */
    *wy = uz;
    *d0_pixel = fma(cx, ux, fma(cy, uy, d0));
    *q_sun = sun ? FOG_NAME(fog_sun_q)((FOG_REAL)0, (FOG_REAL)0, (FOG_REAL)1, lx, ly, lz) : (FOG_REAL)0;
    return FOG_NAME(fog_view_distance)(raw, kind == FOG_DEPTH_RAW ? far_plane : (FOG_REAL)1, kind, 1, reversed_z,
                                       projection, 0, zx, zy, near_plane, far_plane, sky);
  }
  FOG_REAL len = sqrt(fma(cx, cx, fma(cy, cy, cz * cz)));
  FOG_REAL inv = (FOG_REAL)1 / len;
  FOG_REAL wx = cx * inv, wyv = cy * inv, wz = cz * inv;
  *wy = fma(wx, ux, fma(wyv, uy, wz * uz));
  *d0_pixel = d0;
  *q_sun = sun ? FOG_NAME(fog_sun_q)(wx, wyv, wz, lx, ly, lz) : (FOG_REAL)0;
  return FOG_NAME(fog_view_distance)(raw, len, kind, 1, reversed_z, projection, 0, zx, zy, near_plane, far_plane,
                                     sky);
}

/* End of this instance: the includer's instance macros go, so the next instance can define its
 * own (FOG_EXP2 stays: it is written in terms of FOG_NAME). */
#undef FOG_REAL
#undef FOG_INT
#undef FOG_AS_UINT
#undef FOG_TRUNC_INT
#undef FOG_TO_REAL
#undef FOG_AS_REAL
#undef FOG_AS_INT
#undef FOG_CEIL
#undef FOG_FLOOR
#undef FOG_SCALE2
#undef FOG_EXP2_LDEXP
#undef FOG_NAME
#undef FOG_LANES16
