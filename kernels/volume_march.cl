/* volume_march.cl — the march of the fog volumes into the reduced-resolution target
 * (docs/volumetric.md §The march). One work-item per target pixel, global size (ceil(W / s),
 * ceil(H / s)); on CPU devices 16 (VOL_LANES below). The maths is in the shared headers, which
 * the C++ paths compile too.
 *
 * Variant switches (the host's volume_march_options(); none is optional):
 *   VOL_INTEGRATOR   1 stylized, 2 physical, 3 the physical model's textbook Riemann sum (comparison)
 *   VOL_STEPS        march steps per ray
 *   VOL_FEATURES     bit set of VOL_FEATURE_* (noise, detail, fades, shadow map, adaptive steps)
 *   VOL_JITTER       1: per-ray jitter from (pixel, frame index); 0: none
 *   FOG_PROJECTION   0 perspective, 1 reversed-Z infinite far, 2 orthographic
 *   REVERSED_Z       depth 1 at near
 *   VOL_NOISE_IMAGE  the noise is a 3D image read with the sampler's linear filter; else a
 *                    buffer of unorm8 texels filtered by volume_noise.h
 *   VOL_LANES        target pixels per work-item: 16 on CPU devices (noise as a buffer), else 1
 *   FOG_PORTABLE     CPU devices: OpenCL C only, no target builtins (fog_cpu_avx512.h)
 *   VOL_HEIGHT_FEATURES  with VOL_FEATURE_HEIGHT: the marched height fog's FOG_HF_* bits
 *                    (docs/DESIGN.md §6.5); with VOL_FEATURE_HEIGHT_RGB the target holds a
 *                    coverage per channel (volume_composite.h's layout)
 *   VOL_FEATURE_LIGHTS / VOL_FEATURE_SPOT in VOL_FEATURES: local lights, read after the volumes
 *                    (VOL_F_LIGHT_OFFSET), on both instances
 *
 * Why 16 pixels per work-item on CPUs (docs/volumetric.md §Lanes on CPU devices): PoCL vectorises
 * only across work-items, and the march's per-ray loops and branches keep it out, so each core
 * marched one ray at a time. With VOL_LANES 16 a work-item marches 16 adjacent target pixels of
 * a row, one float16 lane each: the per-sample functions of the shared headers are compiled a
 * second time on float16 (volume_common.h), every lane runs all `steps` iterations of each volume
 * some lane enters, and lanes that do not enter it are masked. Setting up the rays and shading a
 * marched volume stay per pixel (the scalar functions, in a loop over the lanes). GPUs keep one
 * pixel per work-item. Global size: (ceil(ceil(W / s) / VOL_LANES), ceil(H / s)), rounded up to
 * whole work-groups (src/runtime/work_groups.h): work-items past the target return.
 */
#pragma OPENCL FP_CONTRACT OFF

#define FOG_EXP2 FOG_NAME(fog_exp2_poly)
#include "fog_math.h" /* the one-pixel instance */

#ifndef VOL_LANES
#define VOL_LANES 1
#endif
#if VOL_LANES > 1
/* Both instances of the shared functions keep their names (volume_common.h). */
#define VOL_FN static inline __attribute__((overloadable))
#endif

#ifdef REVERSED_Z
#define VOL_REVERSED_Z 1
#else
#define VOL_REVERSED_Z 0
#endif
#ifndef VOL_HEIGHT_FEATURES
#define VOL_HEIGHT_FEATURES 0 /* FOG_HF_* bits of the marched height fog (VOL_FEATURE_HEIGHT) */
#endif
#ifndef VOL_DEPTH_KIND
#define VOL_DEPTH_KIND 0 /* FOG_DEPTH_RAW; 1 (FOG_DEPTH_EYE): linear eye depth, read as it is */
#endif

#ifdef VOL_NOISE_IMAGE
constant sampler_t vol_noise_sampler = CLK_NORMALIZED_COORDS_TRUE | CLK_ADDRESS_REPEAT | CLK_FILTER_LINEAR;
#define VOL_NOISE_PARAM read_only image3d_t noise
#define VOL_NOISE_SAMPLE(tex, n, uvw) read_imagef((tex), vol_noise_sampler, (float4)((uvw), 0.0f))
#endif

#include "volume_common.h"
#include "volume_ray.h"
#include "volume_noise.h"
#include "volume_integrate.h"

/* Target pixel i (volume_composite.h's layout): (P, A) and, with a coverage per channel,
 * (A_r, A_g, A_b, 0), A their largest. */
static inline void vol_store_target(global float* low, size_t i, float4 r, const float* coverage) {
#if VOL_FEATURES & VOL_FEATURE_HEIGHT_RGB
  r.w = fmax(coverage[0], fmax(coverage[1], coverage[2]));
  vstore4(r, 2 * i, low);
  vstore4((float4)(coverage[0], coverage[1], coverage[2], 0.0f), 2 * i + 1, low);
#else
  vstore4(r, i, low);
#endif
}

#if VOL_LANES == 1
kernel void volume_march(global const float* depth, global const float* frame, global const float* volumes,
                         int count, VOL_NOISE_PARAM, int noise_size, global const float* shadow_map,
                         uint frame_index, global float* low, global float* low_key) {
  const int lx = get_global_id(0), ly = get_global_id(1);
  const int low_width = (int)frame[VOL_F_LOW_WIDTH];
  if (lx >= low_width || ly >= (int)frame[VOL_F_LOW_HEIGHT]) return;
  float key, coverage[3];
  const float4 r = vol_march_pixel(lx, ly, depth, frame, volumes, count, noise, noise_size, shadow_map, frame_index,
                                   VOL_INTEGRATOR, VOL_STEPS, VOL_FEATURES, VOL_HEIGHT_FEATURES, VOL_JITTER, FOG_PROJECTION,
                                   VOL_REVERSED_Z, VOL_DEPTH_KIND, &key, coverage);
  const size_t i = (size_t)ly * (size_t)low_width + (size_t)lx;
  vol_store_target(low, i, r, coverage);
  low_key[i] = key;
}

#elif VOL_LANES == 16
#if VOL_FEATURES & VOL_FEATURE_HEIGHT
/* The marched height fog's segments lane-wise: fog_math.h's 16-pixel instance (names _v), with the
 * deferred pass's AVX-512 hooks for e^x's floor and 2^n (the same bits: fog_cpu_avx512.h). */
#include "fog_cpu_avx512.h"
#ifdef FOG_AVX512
#define FOG_FLOOR fog_floor_avx512
#define FOG_SCALE2 fog_scale2_avx512
#endif
#define FOG_LANES16
#include "fog_math.h"
#define VOL_LANE_HEIGHT
#endif
#ifdef VOL_NOISE_IMAGE
#error "VOL_LANES 16 reads the noise as a buffer"
#endif
typedef struct { float16 x, y, z; } vol_float3x16;
typedef struct { float16 x, y, z, w; } vol_float4x16;
/* Functions, not compound literals: clang 15 (PoCL 3.1) crashes on a vector cast inside one. */
static inline __attribute__((always_inline)) vol_float3x16 vol_make3_x16(float16 x, float16 y, float16 z) {
  vol_float3x16 v;
  v.x = x, v.y = y, v.z = z;
  return v;
}
static inline __attribute__((always_inline)) vol_float4x16 vol_make4_x16(float16 x, float16 y, float16 z, float16 w) {
  vol_float4x16 v;
  v.x = x, v.y = y, v.z = z, v.w = w;
  return v;
}

/* The four channels of a texel word (bytes R, G, B, A from the lowest) as reals 0..255. */
static inline __attribute__((always_inline)) vol_float4x16 vol_channels_x16(uint16 v) {
  return vol_make4_x16(convert_float16(v & 0xffu), convert_float16((v >> 8) & 0xffu),
                       convert_float16((v >> 16) & 0xffu), convert_float16(v >> 24));
}

/* Texels (x0, y, z) and (x1, y, z) of each lane, interpolated along x by fx (VOL_TEXEL_ROW). A
 * texel is one 4-byte word; both come from one 8-byte load at x0 (x1 = x0 + 1 but where x wraps,
 * whose lanes load the second again), so the x86 gathers fetch 64 elements per sample instead of
 * 128. The buffer is 4-byte aligned and one texel longer than the texture (volume_pass.cpp). */
typedef ulong vol_ulong_a4 __attribute__((aligned(4)));
static inline __attribute__((overloadable, always_inline)) vol_float4x16 vol_lerp4(vol_float4x16 a, vol_float4x16 b,
                                                                                 float16 f);
static inline __attribute__((always_inline)) vol_float4x16 vol_texel_row_x16(global const uchar* tex, int n, int16 x0,
                                                                             int16 x1, int16 y, int16 z, float16 fx) {
  const int16 row = (z * n + y) * n;
  global const uint* words = (global const uint*)tex;
  int at[16];
  uint lo[16], hi[16];
  vstore16(row + x0, 0, at);
#pragma clang loop vectorize_width(16)
  for (int k = 0; k < 16; ++k) {
    const ulong w = *(global const vol_ulong_a4*)(words + at[k]);
    lo[k] = (uint)w;
    hi[k] = (uint)(w >> 32);
  }
  uint16 second = vload16(0, hi);
  const int16 wrapped = x1 != x0 + 1;
  if (VOL_ANY16(wrapped)) {
    int far[16];
    vstore16(row + x1, 0, far);
    for (int k = 0; k < 16; ++k) hi[k] = words[far[k]];
    second = wrapped ? vload16(0, hi) : second;
  }
  return vol_lerp4(vol_channels_x16(vload16(0, lo)), vol_channels_x16(second), fx);
}

/* Slice z of each lane's cell in the R channel alone (VOL_TEXEL_PLANE_R): the buffer holds, after
 * the texture's N^3 texel words and one word of slack, N^3 words of 2 x 2 blocks of R, the word of
 * (x, y, z) bytes R(x, y), R(x + 1, y), R(x, y + 1), R(x + 1, y + 1) (wrapped; built by
 * detail::noise_r_blocks). One 4-byte load per lane gives the slice's four texels. */
static inline __attribute__((overloadable, always_inline)) float16 vol_lerp(float16 a, float16 b, float16 f);
static inline __attribute__((always_inline)) float16 vol_texel_plane_r_x16(global const uchar* tex, int n, int16 x0,
                                                                             int16 y0, int16 z, float16 fx,
                                                                             float16 fy) {
  global const uint* blocks = (global const uint*)tex + (size_t)n * (size_t)n * (size_t)n + 1;
  int at[16];
  uint w[16];
  vstore16((z * n + y0) * n + x0, 0, at);
#pragma clang loop vectorize_width(16)
  for (int k = 0; k < 16; ++k) w[k] = blocks[at[k]];
  const uint16 v = vload16(0, w);
  return vol_lerp(vol_lerp(convert_float16(v & 0xffu), convert_float16((v >> 8) & 0xffu), fx),
                  vol_lerp(convert_float16((v >> 16) & 0xffu), convert_float16(v >> 24), fx), fy);
}

/* Each lane's shadow-map lookup, by the scalar function. */
static inline __attribute__((overloadable)) float16 vol_shadow_lit(vol_float3x16 p, global const float* frame,
                                                                   global const float* shadow_map, int reversed_z) {
  float x[16], y[16], z[16], lit[16];
  vstore16(p.x, 0, x);
  vstore16(p.y, 0, y);
  vstore16(p.z, 0, z);
  for (int k = 0; k < 16; ++k) lit[k] = vol_shadow_lit((float3)(x[k], y[k], z[k]), frame, shadow_map, reversed_z);
  return vload16(0, lit);
}

/* The lanes instance of the per-sample functions (volume_common.h), inlined: LLVM otherwise
 * keeps the trilinear sample a call that passes its structs of float16 through memory. */
#define VOL_LANE_INSTANCE
#undef VOL_FN
#define VOL_FN static inline __attribute__((overloadable, always_inline))
#undef VOL_REAL
#undef VOL_V3
#undef VOL_V4
#undef VOL_MAKE3
#undef VOL_MAKE4
#undef VOL_INT
#undef VOL_TO_INT
#undef VOL_ANY
#undef VOL_TEXEL
#undef VOL_TEXEL_ROW
#undef VOL_UINT
#undef VOL_NOISE_R
#undef VOL_FOG
#define VOL_FOG(name) name##_v
#define VOL_REAL float16
#define VOL_V3 vol_float3x16
#define VOL_V4 vol_float4x16
#define VOL_MAKE3 vol_make3_x16
#define VOL_MAKE4 vol_make4_x16
#define VOL_INT int16
#define VOL_TO_INT(x) convert_int16(x)
#define VOL_ANY(m) VOL_ANY16(m)
#define VOL_UINT uint16
#define VOL_TEXEL_PLANE_R(tex, n, x0, y0, z, fx, fy) vol_texel_plane_r_x16((tex), (n), (x0), (y0), (z), (fx), (fy))
#define VOL_TEXEL_ROW(tex, n, x0, x1, y, z, fx) vol_texel_row_x16((tex), (n), (x0), (x1), (y), (z), (fx))
#include "volume_noise.h"
#include "volume_integrate.h"

#if VOL_INTEGRATOR != VOL_STYLIZED
/* physical: lane k's next piece with volumes from a on (vol_physical's walk): its end *b, its
 * volumes *mask and its segment count *n; 0 when the ray has none left. *pieces counts the pieces
 * walked, as vol_physical's loop does. */
static int vol_lane_next_piece(const float* t_in, const float* t_out, uint hit, int count, float covered, float* a,
                               float* b, uint* mask, float* n, int* pieces) {
  for (; *pieces < 2 * count; ++*pieces) {
    *mask = vol_piece(t_in, t_out, hit, count, *a, b);
    if (!(*b < INFINITY)) return 0;
    if (*mask != 0u) {
      *n = (float)vol_piece_segments(*b - *a, VOL_STEPS, covered);
      ++*pieces;
      return 1;
    }
    *a = *b;
  }
  return 0;
}
#endif

kernel void volume_march(global const float* depth, global const float* frame, global const float* volumes,
                         int count, VOL_NOISE_PARAM, int noise_size, global const float* shadow_map,
                         uint frame_index, global float* low, global float* low_key) {
  const int lx0 = get_global_id(0) * 16, ly = get_global_id(1);
  const int low_width = (int)frame[VOL_F_LOW_WIDTH];
  if (lx0 >= low_width || ly >= (int)frame[VOL_F_LOW_HEIGHT]) return;
  /* Per pixel: the ray, the occluder, the jitter. Lanes past the row's end repeat its last pixel
   * and are not stored. */
  float ox[16], oy[16], oz[16], dx[16], dy[16], dz[16], scene[16], jitter[16], key[16], t_per_eye[16];
  float4 target[16];
  float coverage[16][3];
  for (int k = 0; k < 16; ++k) {
    const int lx = min(lx0 + k, low_width - 1);
    float3 o, d;
    vol_pixel_view(lx, ly, depth, frame, FOG_PROJECTION, VOL_REVERSED_Z, VOL_DEPTH_KIND, &o, &d, &scene[k],
                   &t_per_eye[k], &key[k]);
    ox[k] = o.x, oy[k] = o.y, oz[k] = o.z, dx[k] = d.x, dy[k] = d.y, dz[k] = d.z;
    const float j = vol_jitter((uint)lx, (uint)ly, frame_index);
    jitter[k] = VOL_JITTER ? j : VOL_INTEGRATOR == VOL_STYLIZED ? 0.0f : 0.5f;
    target[k] = (float4)(0.0f);
  }
  const vol_float3x16 origin = vol_make3_x16(vload16(0, ox), vload16(0, oy), vload16(0, oz));
  const vol_float3x16 dir = vol_make3_x16(vload16(0, dx), vload16(0, dy), vload16(0, dz));
  const float16 t_scene = vload16(0, scene), jitter16 = vload16(0, jitter);
#if VOL_INTEGRATOR == VOL_STYLIZED
  for (int i = 0; i < count; ++i) {
    global const float* vol = volumes + i * VOL_V_STRIDE;
    /* The lanes whose ray enters the sphere before the occluder; the others march an empty
     * stretch at the origin and are not shaded. */
    float front[16], back[16];
    int enters[16], any_enters = 0;
    for (int k = 0; k < 16; ++k) {
      float t0, t1;
      const int hit = vol_sphere_hit((float3)(ox[k], oy[k], oz[k]), (float3)(dx[k], dy[k], dz[k]),
                                     VOL_PU3(vol, VOL_V_CENTER), VOL_PU(vol, VOL_V_RADIUS), &t0, &t1) &&
                      t0 < scene[k];
      front[k] = hit ? t0 : 0.0f;
      back[k] = hit ? t1 : 0.0f;
      enters[k] = hit ? -1 : 0;
      any_enters |= hit;
    }
    if (!any_enters) continue;
    const float16 front16 = vload16(0, front);
    float16 reach = vol_stylized_reach(front16, vload16(0, back), t_scene, VOL_PU(vol, VOL_V_OVERSHOOT));
    const int16 active = vload16(0, enters) && reach > 0.0f;
    if (!VOL_ANY16(active)) continue;
    reach = active ? reach : 0.0f;
    float16 accumulation, shadowed, marched;
    vol_stylized_march(origin, dir, front16, reach, jitter16, vol, frame, noise, noise_size, shadow_map, VOL_STEPS,
                       VOL_FEATURES, &accumulation, &shadowed, &marched);
    float acc[16], sh[16], m[16];
    int shade[16];
    vstore16(accumulation, 0, acc);
    vstore16(shadowed, 0, sh);
    vstore16(marched, 0, m);
    vstore16(active && marched > 0.0f, 0, shade);
    for (int k = 0; k < 16; ++k)
      if (shade[k])
        target[k] = vol_over(target[k], vol_stylized_shade((float3)(dx[k], dy[k], dz[k]), acc[k], sh[k], m[k], vol,
                                                           frame, VOL_FEATURES));
  }
  for (int k = 0; k < 16; ++k) coverage[k][0] = coverage[k][1] = coverage[k][2] = target[k].w;
#else
  /* physical: each lane walks its ray's pieces and segments as vol_physical does; an iteration
   * takes every live lane's next segment, so all lanes sample at once while their pieces differ.
   * Lanes whose ray is done sample nothing (an empty mask) until the last one is. */
  float t_in[16][VOL_MAX_VOLUMES], t_out[16][VOL_MAX_VOLUMES];
  float a[16], b[16], covered[16], n[16], j[16], cos_theta[16], start[16];
  uint hit[16], mask[16];
  int live[16], pieces[16];
#if VOL_FEATURES & VOL_FEATURE_HEIGHT
  /* The marched height fog walks as volume `count` (vol_physical); its segments go lane-wise, an
   * infinite ray's tail and the fog's light per lane (vol_height_finish). */
  const int walked = count + 1;
  const uint fog_bit = 1u << count;
  float hp[FOG_HP_COUNT], s_origin[16], d0[16], tail_from[16];
  int infinite[16];
  for (int i = 0; i < FOG_HP_COUNT; ++i) hp[i] = frame[VOL_F_HEIGHT_P + i];
#else
  const int walked = count;
#endif
  for (int k = 0; k < 16; ++k) {
    const float3 o = (float3)(ox[k], oy[k], oz[k]), d = (float3)(dx[k], dy[k], dz[k]);
    hit[k] = vol_physical_hits(o, d, scene[k], volumes, count, t_in[k], t_out[k], &a[k]);
#if VOL_FEATURES & VOL_FEATURE_HEIGHT
    vol_height_ray(o, d, scene[k], t_per_eye[k], frame, hp, VOL_HEIGHT_FEATURES, count, t_in[k], t_out[k], &hit[k],
                   &a[k], &s_origin[k], &d0[k], &tail_from[k], &infinite[k]);
#endif
    start[k] = fmin(a[k], 0.0f); /* where the local lights' stretches may begin (vol_physical) */
    cos_theta[k] = dot(d, VOL_PU3(frame, VOL_F_LIGHT_DIR));
    covered[k] = hit[k] != 0u ? vol_covered(t_in[k], t_out[k], hit[k], walked, a[k]) : 0.0f;
    pieces[k] = 0;
    j[k] = 0.0f;
    const int first = hit[k] != 0u && vol_lane_next_piece(t_in[k], t_out[k], hit[k], walked, covered[k], &a[k], &b[k],
                                                          &mask[k], &n[k], &pieces[k]);
    live[k] = first ? -1 : 0;
  }
  float16 phase[VOL_MAX_VOLUMES];
  vol_physical_phases(vload16(0, cos_theta), volumes, count, phase);
#if VOL_FEATURES & VOL_FEATURE_LIGHTS
  /* The local lights that some lane's ray meets, their constants lane-wise (vol_physical's). */
  float16 lr[VOL_MAX_LIGHTS * VOL_LR_STRIDE], each[VOL_MAX_VOLUMES];
  int light_ids[VOL_MAX_LIGHTS];
  global const float* lights = volumes + (int)frame[VOL_F_LIGHT_OFFSET];
  const int ray_lights = vol_light_rays(origin, dir, vload16(0, start), t_scene, lights, (int)frame[VOL_F_LIGHT_COUNT],
                                        VOL_FEATURES, lr, light_ids);
#else
  float16* each = 0;
#endif
  float16 i_r = 0.0f, i_g = 0.0f, i_b = 0.0f, optical = 0.0f;
  float16 s1 = 0.0f; /* each lane's last segment end: the next segment's start within a piece */
#if VOL_FEATURES & VOL_FEATURE_HEIGHT
  /* The fog's sums per channel (channel 0 alone where the coefficients are grey), as vol_physical's. */
  float16 fog_ext[3] = {0.0f, 0.0f, 0.0f}, fog_in[3] = {0.0f, 0.0f, 0.0f}, fog_sun_depth[3] = {0.0f, 0.0f, 0.0f};
  float16 fog_amb[3] = {0.0f, 0.0f, 0.0f}, fog_sun[3] = {0.0f, 0.0f, 0.0f};
  const float16 s_origin16 = vload16(0, s_origin), d0_16 = vload16(0, d0);
  const int fog_channels = (VOL_HEIGHT_FEATURES & FOG_HF_RGB) ? 3 : 1;
  const int channels = (VOL_FEATURES & VOL_FEATURE_HEIGHT_RGB) ? 3 : 1;
#endif
  for (;;) {
    const int16 alive = vload16(0, live);
    if (!VOL_ANY16(alive)) break;
    const float16 pa = alive ? vload16(0, a) : 0.0f, pb = alive ? vload16(0, b) : 0.0f;
    const float16 pn = alive ? vload16(0, n) : 1.0f, pj = vload16(0, j);
    const float16 length = pb - pa;
    const float16 s0 = pj == 0.0f ? pa : s1;
    s1 = pj + 1.0f == pn ? pb : vol_segment_start(pa, length, pj + 1.0f, pn);
    const float16 seg = s1 - s0, t = s0 + jitter16 * seg;
    const vol_float3x16 p = vol_make3_x16(origin.x + dir.x * t, origin.y + dir.y * t, origin.z + dir.z * t);
    float16 lit = 1.0f;
    if (VOL_FEATURES & VOL_FEATURE_SHADOW)
      lit = vol_shadow_lit(p, frame, shadow_map, VOL_FEATURES & VOL_FEATURE_SHADOW_REVERSED);
    vol_float3x16 source;
    const uint16 volumes_here = alive ? vload16(0, mask) : (uint16)0u;
    const float16 sigma_t = vol_physical_sample(p, t, phase, lit, volumes_here, volumes, count, frame, noise,
                                                noise_size, VOL_FEATURES, &source, each);
    const int16 adds = sigma_t > 0.0f;
#if VOL_FEATURES & VOL_FEATURE_HEIGHT
    /* vol_physical's fog segment, on the lanes whose segment has the fog; extinctions add. */
    const int16 fogged = (volumes_here & fog_bit) != 0u;
    const float16 ext_before[3] = {fog_ext[0], fog_ext[1], fog_ext[2]};
    const float16 in_before[3] = {fog_in[0], fog_in[1], fog_in[2]};
    if (VOL_ANY16(fogged)) {
      float16 e[3], in[3], sd[3], am[3], su[3];
      for (int c = 0; c < fog_channels; ++c)
        e[c] = fog_ext[c], in[c] = fog_in[c], sd[c] = fog_sun_depth[c], am[c] = fog_amb[c], su[c] = fog_sun[c];
      /* Without volumes in any lane's segment (the fog alone, mostly) the fog's share of the
       * scattering is 1 at compile time: no division for it. */
      if (VOL_ANY16(adds))
        vol_height_segment(s0, s1, s_origin16, dir.y, d0_16, lit, adds ? sigma_t * seg : 0.0f, optical, hp,
                           VOL_HEIGHT_FEATURES, e, in, sd, am, su);
      else
        vol_height_segment(s0, s1, s_origin16, dir.y, d0_16, lit, (float16)0.0f, optical, hp, VOL_HEIGHT_FEATURES, e,
                           in, sd, am, su);
      for (int c = 0; c < fog_channels; ++c) {
        fog_ext[c] = fogged ? e[c] : fog_ext[c];
        fog_in[c] = fogged ? in[c] : fog_in[c];
        fog_sun_depth[c] = fogged ? sd[c] : fog_sun_depth[c];
        fog_amb[c] = fogged ? am[c] : fog_amb[c];
        fog_sun[c] = fogged ? su[c] : fog_sun[c];
      }
    }
#if VOL_FEATURES & VOL_FEATURE_LIGHTS
    if (ray_lights > 0) { /* lanes without a medium in their segment scatter nothing */
      const vol_float3x16 l = vol_segment_lights(s0, s1, sigma_t, optical, fogged, ext_before, fog_ext, in_before,
                                                 fog_in, fog_channels == 3, channels, each, volumes_here, volumes,
                                                 count, lights, lr, light_ids, ray_lights, VOL_FEATURES);
      i_r += l.x;
      i_g += l.y;
      i_b += l.z;
    }
#endif
    if (VOL_ANY16(adds)) {
      float16 scatter[3];
      for (int c = 0; c < channels; ++c)
        scatter[c] = vol_segment_weight(fogged ? sigma_t + (fog_ext[c] - ext_before[c]) / seg : sigma_t, seg,
                                        optical + ext_before[c], VOL_INTEGRATOR == VOL_RIEMANN);
      if (channels == 1) scatter[1] = scatter[2] = scatter[0];
      i_r = adds ? i_r + source.x * scatter[0] : i_r;
      i_g = adds ? i_g + source.y * scatter[1] : i_g;
      i_b = adds ? i_b + source.z * scatter[2] : i_b;
      optical = adds ? optical + sigma_t * seg : optical;
    }
#else
#if VOL_FEATURES & VOL_FEATURE_LIGHTS
    if (ray_lights > 0 && VOL_ANY16(adds)) {
      const float16 none[3] = {0.0f, 0.0f, 0.0f}; /* no marched fog */
      const vol_float3x16 l = vol_segment_lights(s0, s1, sigma_t, optical, (int16)0, none, none, none, none, 0, 1,
                                                 each, volumes_here, volumes, count, lights, lr, light_ids,
                                                 ray_lights, VOL_FEATURES);
      i_r += l.x;
      i_g += l.y;
      i_b += l.z;
    }
#endif
    if (VOL_ANY16(adds)) {
      const float16 scatter = vol_segment_weight(sigma_t, seg, optical, VOL_INTEGRATOR == VOL_RIEMANN);
      i_r = adds ? i_r + source.x * scatter : i_r;
      i_g = adds ? i_g + source.y * scatter : i_g;
      i_b = adds ? i_b + source.z * scatter : i_b;
      optical = adds ? optical + sigma_t * seg : optical;
    }
#endif
    vstore16(pj + 1.0f, 0, j);
    const int16 piece_ends = alive && pj + 1.0f == pn;
    if (!VOL_ANY16(piece_ends)) continue;
    int ends[16];
    vstore16(piece_ends, 0, ends);
    for (int k = 0; k < 16; ++k)
      if (ends[k]) {
        a[k] = b[k];
        j[k] = 0.0f;
        live[k] = vol_lane_next_piece(t_in[k], t_out[k], hit[k], walked, covered[k], &a[k], &b[k], &mask[k], &n[k],
                                      &pieces[k]) ? -1 : 0;
      }
  }
  float r[16], g[16], bl[16], cov[16];
  vstore16(i_r, 0, r);
  vstore16(i_g, 0, g);
  vstore16(i_b, 0, bl);
#if VOL_FEATURES & VOL_FEATURE_HEIGHT
  vstore16(optical, 0, cov);
  float sums[5][3][16]; /* the fog's ext, in, sun depth, ambient, sun sums per channel and lane */
  for (int c = 0; c < fog_channels; ++c) {
    vstore16(fog_ext[c], 0, sums[0][c]);
    vstore16(fog_in[c], 0, sums[1][c]);
    vstore16(fog_sun_depth[c], 0, sums[2][c]);
    vstore16(fog_amb[c], 0, sums[3][c]);
    vstore16(fog_sun[c], 0, sums[4][c]);
  }
  for (int k = 0; k < 16; ++k) {
    if (hit[k] == 0u && !infinite[k]) { /* no fog, no volume: vol_physical's early return */
      target[k] = (float4)(0.0f);
      coverage[k][0] = coverage[k][1] = coverage[k][2] = 0.0f;
      continue;
    }
    float e[3], in[3], sd[3], am[3], su[3];
    for (int c = 0; c < fog_channels; ++c)
      e[c] = sums[0][c][k], in[c] = sums[1][c][k], sd[c] = sums[2][c][k], am[c] = sums[3][c][k], su[c] = sums[4][c][k];
    target[k] = vol_height_finish((float3)(ox[k], oy[k], oz[k]), (float3)(dx[k], dy[k], dz[k]), tail_from[k],
                                  infinite[k], s_origin[k], d0[k], cov[k], (float3)(r[k], g[k], bl[k]), hp,
                                  VOL_HEIGHT_FEATURES, frame, shadow_map, VOL_FEATURES, e, in, sd, am, su,
                                  coverage[k]);
  }
#else
  vstore16(-expm1(-optical), 0, cov);
  for (int k = 0; k < 16; ++k) {
    target[k] = (float4)(r[k], g[k], bl[k], cov[k]);
    coverage[k][0] = coverage[k][1] = coverage[k][2] = cov[k];
  }
#endif
#endif
  const int lanes = min(16, low_width - lx0);
  for (int k = 0; k < lanes; ++k) {
    const size_t at = (size_t)ly * (size_t)low_width + (size_t)(lx0 + k);
    vol_store_target(low, at, target[k], coverage[k]);
    low_key[at] = key[k];
  }
}
#else
#error "VOL_LANES must be 1 or 16"
#endif
