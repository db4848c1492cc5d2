/* volume_composite.h — the target back to full resolution and over the frame
 * (docs/volumetric.md §Resolution, upsampling, composite). Needs volume_common.h and the
 * one-pixel instance of fog_math.h (the depth formulas). */

/* Depth tolerance of the depth-aware upsampling: a tap whose depth difference (below) is at most
 * this is on the pixel's own surface. A tap's weight is its bilinear weight over max(difference,
 * VOL_UPSAMPLE_EPS), so taps on the pixel's surface win 100 : 1 over taps across a silhouette
 * (difference 1, the cap), and a pixel whose four taps are all on its surface takes the bilinear
 * weights exactly (vol_upsample; docs/volumetric.md §Resolution, upsampling, composite). */
#define VOL_UPSAMPLE_EPS 0.01f

/* The depth difference of a frame pixel (eye depth e) and a tap (the target's key k, the eye depth
 * it marched to) is |k - e| / e capped at 1, evaluated as |1 - k rho| with rho = 1 / e from
 * vol_inverse_eye_depth: one fma per tap, no division (docs/volumetric.md, §Resolution,
 * upsampling, composite). Sky is k = VOL_KEY_SKY (the march's +inf, capped) and rho = VOL_RHO_SKY,
 * whose product is exactly 1: sky against sky differs by 0, sky against a surface (eye depths
 * below 2^100) by 1, with no inf * 0. */
#define VOL_KEY_SKY 0x1p126f
#define VOL_RHO_SKY 0x1p-126f
/* Linear01Depth = 1 / q is sky (fog_is_sky: > 0.9999f, rounded as float) exactly when q is below
 * this float (tests/volume_composite_test.cpp checks it and its neighbour). */
#define VOL_SKY_DENOMINATOR 0x1.00068ep+0f

/* 1 / eye depth of a frame pixel, from its raw depth (or linear eye depth, `kind`): linear in the depth buffer for perspective
 * cameras (q / far, q the denominator of Linear01Depth; raw / near with an infinite far plane), so
 * the composite needs no division for it. VOL_RHO_SKY for sky, and never below it. */
VOL_FN VOL_REAL vol_inverse_eye_depth(VOL_REAL raw, VOL_GLOBAL const float* frame, int projection, int reversed_z,
                                      int kind) {
  const VOL_REAL zx = VOL_P(frame, VOL_F_ZX), zy = VOL_P(frame, VOL_F_ZY);
  const VOL_REAL depth = fog_sanitize_depth(raw, reversed_z);
  VOL_REAL rho;
  int sky;
  if (kind != FOG_DEPTH_RAW) { /* linear eye depth (vol_eye_depth): one division */
    rho = (VOL_REAL)1 / fog_clamp_linear_depth(raw, VOL_P(frame, VOL_F_NEAR), VOL_P(frame, VOL_F_FAR), &sky);
  } else if (projection == FOG_PROJECTION_INFINITE_FAR) {
    sky = depth == (VOL_REAL)0;
    rho = depth * VOL_P(frame, VOL_F_INV_NEAR);
  } else if (projection == FOG_PROJECTION_ORTHOGRAPHIC) {
    const VOL_REAL linear01 = fog_linear01_depth_ortho(depth, zx, zy);
    sky = fog_is_sky(linear01);
    rho = (VOL_REAL)1 / (linear01 * VOL_P(frame, VOL_F_FAR));
  } else {
    const VOL_REAL q = fog_linear01_denominator(depth, zx, zy, reversed_z);
    sky = q < (VOL_REAL)VOL_SKY_DENOMINATOR;
    rho = q * VOL_P(frame, VOL_F_INV_FAR);
  }
  return sky ? (VOL_REAL)VOL_RHO_SKY : (rho > (VOL_REAL)VOL_RHO_SKY ? rho : (VOL_REAL)VOL_RHO_SKY);
}

/* The depth difference above, in [0, 1], for rho from vol_inverse_eye_depth and a target key k
 * (an eye depth > 0, or +inf; NaN counts as sky). */
VOL_FN VOL_REAL vol_depth_difference(VOL_REAL rho, VOL_REAL k) {
  const VOL_REAL key = k < (VOL_REAL)VOL_KEY_SKY ? k : (VOL_REAL)VOL_KEY_SKY;
  const VOL_REAL d = fabs(fma(-key, rho, (VOL_REAL)1));
  return d < (VOL_REAL)1 ? d : (VOL_REAL)1;
}

/* a * w + c by component, each rounded once (GLM's fma is a * b + c). */
VOL_FN VOL_V4 vol_fma4(VOL_V4 a, VOL_REAL w, VOL_V4 c) {
  return VOL_MAKE4(fma(a.x, w, c.x), fma(a.y, w, c.y), fma(a.z, w, c.z), fma(a.w, w, c.w));
}

/* Along one axis: the two target pixels around full-resolution coordinate x (their centres are
 * block centres; edges clamp) in *i0, *i1, and the bilinear weight of *i1. At s = 2 and 4 the
 * weight is never 0 or 1; every step is exact (powers of 2, small integers). */
VOL_FN VOL_REAL vol_upsample_axis(int x, int scale, int low_size, int* i0, int* i1) {
  const VOL_REAL g = ((VOL_REAL)x + (VOL_REAL)0.5f) / (VOL_REAL)scale - (VOL_REAL)0.5f;
  const VOL_REAL f0 = floor(g);
  *i0 = max((int)f0, 0);
  *i1 = min((int)f0 + 1, low_size - 1);
  return g - f0;
}

/* The target's layout: per target pixel (P premultiplied RGB, A), 4 floats, and where the marched
 * fog's extinction differs per channel (VOL_FEATURE_HEIGHT_RGB; the composite's VOL_TARGET_RGB)
 * the coverage per channel (A_r, A_g, A_b, 0) after it, 8 floats, A then being their largest
 * (what tells a pixel with fog from one without). */
#define VOL_TARGET_FLOATS(rgb) ((rgb) ? 8 : 4)

/* The upsampling of the target at full-resolution pixel (x, y) of inverse eye depth rho
 * (vol_inverse_eye_depth): the 2 x 2 nearest target pixels (their indices in at[4]) and their
 * weights w[4], bilinear, or bilinear x depth similarity when depth_aware; returns whether the
 * weights' sum is to be normalised (vol_upsample_taps). Scale 1 gives the pixel's own sample,
 * weight 1. */
VOL_FN int vol_upsample_weights(int x, int y, VOL_REAL rho, VOL_GLOBAL const VOL_REAL* low_key, int low_width,
                                int low_height, int scale, int depth_aware, size_t* at, VOL_REAL* w) {
  if (scale == 1) {
    at[0] = at[1] = at[2] = at[3] = (size_t)y * (size_t)low_width + (size_t)x;
    w[0] = (VOL_REAL)1;
    w[1] = w[2] = w[3] = (VOL_REAL)0;
    return 0;
  }
  int x0, x1, y0, y1;
  const VOL_REAL fx = VOL_T(vol_upsample_axis)(x, scale, low_width, &x0, &x1);
  const VOL_REAL fy = VOL_T(vol_upsample_axis)(y, scale, low_height, &y0, &y1);
  const int xs[4] = {x0, x1, x0, x1}, ys[4] = {y0, y0, y1, y1};
  for (int k = 0; k < 4; ++k) at[k] = (size_t)ys[k] * (size_t)low_width + (size_t)xs[k];
  w[0] = ((VOL_REAL)1 - fx) * ((VOL_REAL)1 - fy);
  w[1] = fx * ((VOL_REAL)1 - fy);
  w[2] = ((VOL_REAL)1 - fx) * fy;
  w[3] = fx * fy;
  /* Depth-aware weights are bilinear[k] / e[k], e[k] = max(depth difference, EPS) in [0.01, 1],
   * here scaled by e0 e1 e2 e3 (the sum is normalised): products that cannot overflow or
   * underflow instead of 4 divisions, and one reciprocal of their sum. A pixel whose four
   * differences are all within EPS (its own surface, every e[k] = EPS) takes the bilinear weights
   * as they are, the value the normalised products have in exact arithmetic: the CPU lanes skip
   * the products for blocks of such pixels. Bilinear weights sum to exactly 1 at s = 2 and 4: no
   * normalisation. */
  int normalise = 0;
  if (depth_aware) {
    VOL_REAL d[4];
    for (int k = 0; k < 4; ++k) {
      d[k] = VOL_T(vol_depth_difference)(rho, (VOL_REAL)low_key[at[k]]);
      normalise |= d[k] > (VOL_REAL)VOL_UPSAMPLE_EPS; /* d is never NaN */
    }
    if (normalise) {
      VOL_REAL e[4];
      for (int k = 0; k < 4; ++k) e[k] = d[k] > (VOL_REAL)VOL_UPSAMPLE_EPS ? d[k] : (VOL_REAL)VOL_UPSAMPLE_EPS;
      const VOL_REAL e01 = e[0] * e[1], e23 = e[2] * e[3];
      w[0] = w[0] * (e[1] * e23);
      w[1] = w[1] * (e[0] * e23);
      w[2] = w[2] * (e[3] * e01);
      w[3] = w[3] * (e[2] * e01);
    }
  }
  return normalise;
}

/* The 4 floats from `offset` of each target pixel (stride floats apart) under the weights of
 * vol_upsample_weights. One weight of 1 (scale 1) returns its tap unchanged. */
VOL_FN VOL_V4 vol_upsample_taps(VOL_GLOBAL const VOL_REAL* low, int stride, int offset, const size_t* at,
                                const VOL_REAL* w, int normalise, int scale) {
  VOL_V4 tap[4];
  for (int k = 0; k < (scale == 1 ? 1 : 4); ++k) {
    const size_t i = (size_t)stride * at[k] + (size_t)offset;
    tap[k] = VOL_MAKE4(VOL_P(low, i), VOL_P(low, i + 1), VOL_P(low, i + 2), VOL_P(low, i + 3));
  }
  if (scale == 1) return tap[0];
  /* Row by row, then normalised: two short chains, and the CPU lanes' division overlaps them. */
  const VOL_V4 sum = VOL_T(vol_fma4)(tap[1], w[1], tap[0] * w[0]) + VOL_T(vol_fma4)(tap[3], w[3], tap[2] * w[2]);
  return normalise ? sum * ((VOL_REAL)1 / ((w[0] + w[1]) + (w[2] + w[3]))) : sum;
}

/* The target (P, A) of a target of 4 floats per pixel at full-resolution pixel (x, y) of inverse
 * eye depth rho: vol_upsample_weights' taps. Scale 1 returns the pixel's own sample unchanged. */
VOL_FN VOL_V4 vol_upsample(int x, int y, VOL_REAL rho, VOL_GLOBAL const VOL_REAL* low, VOL_GLOBAL const VOL_REAL* low_key,
                           int low_width, int low_height, int scale, int depth_aware) {
  size_t at[4];
  VOL_REAL w[4];
  const int normalise =
      VOL_T(vol_upsample_weights)(x, y, rho, low_key, low_width, low_height, scale, depth_aware, at, w);
  return VOL_T(vol_upsample_taps)(low, 4, 0, at, w, normalise, scale);
}

/* One channel over the fog (docs/volumetric.md §Resolution, upsampling, composite): P + c (1 - A),
 * one rounding. A == 1 writes P exactly (a hidden NaN/Inf never leaks); the caller passes A == 0
 * pixels through bit for bit. */
VOL_FN VOL_REAL vol_composite(VOL_REAL c, VOL_REAL premultiplied, VOL_REAL coverage) {
  return coverage == (VOL_REAL)1 ? premultiplied : fma(c, (VOL_REAL)1 - coverage, premultiplied);
}
