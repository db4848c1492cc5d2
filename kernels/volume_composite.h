/* volume_composite.h — the target back to full resolution and over the frame
 * (docs/volumetric.md §Resolution, upsampling, composite). Needs volume_common.h. */

/* Weight floor of the depth-aware upsampling: a tap's weight is its bilinear weight over
 * (VOL_UPSAMPLE_EPS + relative depth difference), so taps on the pixel's own surface win about
 * 50 : 1 over taps across a silhouette, and taps on one surface keep plain bilinear weights. */
#define VOL_UPSAMPLE_EPS 0.01f

/* |a - b| / max(a, b) for eye depths >= 0 (+inf for sky): 0 for equal depths, sky included, 1
 * between sky and a surface. Written (a - b) * (1 / max(a, b)), at most 1: the CPU lanes take the
 * reciprocal once per depth, not once per pair (min(1/a, 1/b) rounds as 1/max(a, b) does), so
 * the composite does 4 divisions per 16 pixels instead of 12. */
VOL_FN VOL_REAL vol_depth_difference(VOL_REAL a, VOL_REAL b) {
  const VOL_REAL hi = fmax(a, b), lo = fmin(a, b);
  if (hi == lo) return (VOL_REAL)0;
  if (!(hi < (VOL_REAL)INFINITY)) return (VOL_REAL)1;
  return fmin((hi - lo) * ((VOL_REAL)1 / hi), (VOL_REAL)1);
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

/* The target (P, A) at full-resolution pixel (x, y) of eye depth `key`: the 2 x 2 nearest target
 * pixels, bilinear, or bilinear x depth similarity when depth_aware. Scale 1 returns the pixel's
 * own sample unchanged. */
VOL_FN VOL_V4 vol_upsample(int x, int y, VOL_REAL key, VOL_GLOBAL const VOL_REAL* low, VOL_GLOBAL const VOL_REAL* low_key,
                           int low_width, int low_height, int scale, int depth_aware) {
  if (scale == 1) {
    const size_t i = (size_t)y * (size_t)low_width + (size_t)x;
    return VOL_MAKE4(VOL_P(low, 4 * i), VOL_P(low, 4 * i + 1), VOL_P(low, 4 * i + 2), VOL_P(low, 4 * i + 3));
  }
  int x0, x1, y0, y1;
  const VOL_REAL fx = VOL_T(vol_upsample_axis)(x, scale, low_width, &x0, &x1);
  const VOL_REAL fy = VOL_T(vol_upsample_axis)(y, scale, low_height, &y0, &y1);
  const int xs[4] = {x0, x1, x0, x1}, ys[4] = {y0, y0, y1, y1};
  const VOL_REAL bilinear[4] = {((VOL_REAL)1 - fx) * ((VOL_REAL)1 - fy), fx * ((VOL_REAL)1 - fy),
                                ((VOL_REAL)1 - fx) * fy, fx * fy};
  /* Depth-aware weights are bilinear[k] / e[k], e[k] = EPS + depth difference in [0.01, 1.01],
   * here scaled by e0 e1 e2 e3 (the result is normalised): products that cannot overflow or
   * underflow instead of 4 divisions. Bilinear weights sum to exactly 1 at s = 2 and 4. */
  VOL_REAL w[4] = {bilinear[0], bilinear[1], bilinear[2], bilinear[3]};
  if (depth_aware) {
    VOL_REAL e[4];
    for (int k = 0; k < 4; ++k)
      e[k] = (VOL_REAL)VOL_UPSAMPLE_EPS +
             VOL_T(vol_depth_difference)(key, (VOL_REAL)low_key[(size_t)ys[k] * (size_t)low_width + (size_t)xs[k]]);
    const VOL_REAL e01 = e[0] * e[1], e23 = e[2] * e[3];
    w[0] = bilinear[0] * (e[1] * e23);
    w[1] = bilinear[1] * (e[0] * e23);
    w[2] = bilinear[2] * (e[3] * e01);
    w[3] = bilinear[3] * (e[2] * e01);
  }
  VOL_V4 sum = VOL_MAKE4((VOL_REAL)0, (VOL_REAL)0, (VOL_REAL)0, (VOL_REAL)0);
  VOL_REAL weight = 0;
  for (int k = 0; k < 4; ++k) {
    const size_t i = (size_t)ys[k] * (size_t)low_width + (size_t)xs[k];
    sum = sum + VOL_MAKE4(VOL_P(low, 4 * i), VOL_P(low, 4 * i + 1), VOL_P(low, 4 * i + 2), VOL_P(low, 4 * i + 3)) * w[k];
    weight += w[k];
  }
  return depth_aware ? sum * ((VOL_REAL)1 / weight) : sum;
}

/* One channel over the fog (docs/volumetric.md §Resolution, upsampling, composite): P + c (1 - A). A == 1 writes P exactly (a hidden
 * NaN/Inf never leaks); the caller passes A == 0 pixels through bit for bit. */
VOL_FN VOL_REAL vol_composite(VOL_REAL c, VOL_REAL premultiplied, VOL_REAL coverage) {
  return coverage == (VOL_REAL)1 ? premultiplied : premultiplied + c * ((VOL_REAL)1 - coverage);
}
