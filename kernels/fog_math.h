/* fog_math.h — the per-pixel formulas of DESIGN.md §2, written once and compiled twice:
 *   - by the OpenCL kernels (OpenCL C, FOG_REAL = float), and
 *   - by the C++ scalar path (FOG_FN makes each function a template on FOG_REAL, so the same
 *     text runs in float for the baseline and in double for the reference).
 * Only scalar operations available in both languages appear here: fma, exp2, sqrt, fmin, fmax.
 * Sources: Unity's UnityCG.cginc (Linear01Depth, UNITY_CALC_FOG_FACTOR_RAW) and Catlike Coding,
 * "Rendering 14: Fog" (deferred fog, depth vs distance, the skybox test). */
#ifndef FOGCL_FOG_MATH_H
#define FOGCL_FOG_MATH_H

#ifdef __OPENCL_C_VERSION__
#define FOG_REAL float
#define FOG_FN static inline
#else
#define FOG_FN template <typename FOG_REAL> inline
#endif

/* Pixel centre to Unity uv: u grows to the right, v grows upwards (row 0 is the top row). */
FOG_FN FOG_REAL fog_pixel_u(int x, int width) {
  return ((FOG_REAL)x + (FOG_REAL)0.5f) / (FOG_REAL)width;
}
FOG_FN FOG_REAL fog_pixel_v(int y, int height) {
  return (FOG_REAL)1 - ((FOG_REAL)y + (FOG_REAL)0.5f) / (FOG_REAL)height;
}

/* One component of the pixel's far-plane ray: bilinear interpolation of the corners
 * (bottom-left, bottom-right, top-left, top-right), as the rasterised full-screen quad does. */
FOG_FN FOG_REAL fog_bilerp(FOG_REAL bl, FOG_REAL br, FOG_REAL tl, FOG_REAL tr, FOG_REAL u,
                           FOG_REAL v) {
  FOG_REAL bottom = bl + (br - bl) * u;
  FOG_REAL top = tl + (tr - tl) * u;
  return bottom + (top - bottom) * v;
}

/* Raw depth outside [0, 1] is clamped; NaN becomes the far value (sky). fmin/fmax return the
 * non-NaN operand, so the order of the two calls decides where a NaN lands. */
FOG_FN FOG_REAL fog_sanitize_depth(FOG_REAL raw, int reversed_z) {
  return reversed_z ? fmin(fmax(raw, (FOG_REAL)0), (FOG_REAL)1)
                    : fmax(fmin(raw, (FOG_REAL)1), (FOG_REAL)0);
}

/* Linear01Depth = 1 / (x * raw + y). The fma matters: with conventional Z, x * raw and y nearly
 * cancel for far pixels (|x| = far/near), and rounding the product first costs up to
 * far/near ulps; the fused form has a single rounding. */
FOG_FN FOG_REAL fog_linear01_depth(FOG_REAL raw, FOG_REAL zx, FOG_REAL zy) {
  return (FOG_REAL)1 / fma(zx, raw, zy);
}

/* Catlike's skybox test, the same in both Z conventions (the far plane is at Linear01 = 1). */
FOG_FN int fog_is_sky(FOG_REAL linear01) { return linear01 > (FOG_REAL)0.9999f; }

/* Depth-based view distance: Linear01Depth * far - near (Unity's fog coordinate). */
FOG_FN FOG_REAL fog_depth_distance(FOG_REAL linear01, FOG_REAL near_plane, FOG_REAL far_plane) {
  return fma(linear01, far_plane, -near_plane);
}

/* Distance-based: |ray * Linear01Depth| where ray is the far-plane corner ray of the pixel. */
FOG_FN FOG_REAL fog_radial_distance(FOG_REAL linear01, FOG_REAL rx, FOG_REAL ry, FOG_REAL rz) {
  return linear01 * sqrt(rx * rx + ry * ry + rz * rz);
}

FOG_FN FOG_REAL fog_saturate(FOG_REAL f) { return fmin(fmax(f, (FOG_REAL)0), (FOG_REAL)1); }

/* Linear: f = (end - d) / (end - start), inv_range = 1 / (end - start) > 0. Subtracting first
 * keeps f exact near d == end, where Unity's d * (-inv) + end * inv cancels. */
FOG_FN FOG_REAL fog_factor_linear(FOG_REAL d, FOG_REAL end, FOG_REAL inv_range) {
  return fog_saturate((end - d) * inv_range);
}

/* Linear with start == end: a hard step, 1 before start, 0 from start on. */
FOG_FN FOG_REAL fog_factor_step(FOG_REAL d, FOG_REAL start) {
  return d < start ? (FOG_REAL)1 : (FOG_REAL)0;
}

/* Exp: f = exp2(-d * density / ln 2) = e^(-density d); k = density * log2(e). */
FOG_FN FOG_REAL fog_factor_exp(FOG_REAL d, FOG_REAL k) {
  return fog_saturate(exp2(-(d * k)));
}

/* Exp2: f = exp2(-(d * density / sqrt(ln 2))^2) = e^(-(density d)^2); k = density / sqrt(ln 2).
 * A huge d * k squares to +inf and exp2(-inf) = 0: no NaN. */
FOG_FN FOG_REAL fog_factor_exp2(FOG_REAL d, FOG_REAL k) {
  FOG_REAL t = d * k;
  return fog_saturate(exp2(-(t * t)));
}

/* Blend one channel: fogColor + f * (c - fogColor). f == 1 returns c untouched (bit-exact, NaN
 * and Inf included) and f == 0 returns exactly the fog color (a hidden NaN never leaks). */
FOG_FN FOG_REAL fog_blend(FOG_REAL c, FOG_REAL fog_color, FOG_REAL f) {
  return f == (FOG_REAL)1 ? c : (f == (FOG_REAL)0 ? fog_color : fma(f, c - fog_color, fog_color));
}

#endif /* FOGCL_FOG_MATH_H */
