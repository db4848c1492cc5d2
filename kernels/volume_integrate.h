/* volume_integrate.h — the two integrators of the march (docs/volumetric.md §The march) and the
 * per-pixel entry both the kernel and the C++ paths run. Needs volume_common.h, volume_ray.h and
 * volume_noise.h.
 *
 * features: a bit set of VOL_FEATURE_* (compile-time constants in the kernel, so a variant holds
 * no code for what the scene does not use). */
#define VOL_FEATURE_NOISE 1          /* some volume has noise: sample the shape noise */
#define VOL_FEATURE_DETAIL 2         /* ... and detail noise (detail_strength > 0 somewhere) */
#define VOL_FEATURE_FADES 4          /* some fade can be below 1 */
#define VOL_FEATURE_SHADOW 8         /* a shadow map is bound */
#define VOL_FEATURE_SHADOW_REVERSED 16 /* ... holding reversed Z */
#define VOL_FEATURE_ADAPTIVE 32      /* stylized: the seed's adaptive stepping */
#define VOL_FEATURE_HEIGHT 64        /* physical: the height fog marched (docs/DESIGN.md §6.5); its
                                      * FOG_HF_* bits are VOL_HEIGHT_FEATURES */
#define VOL_FEATURE_HEIGHT_RGB 128   /* ... whose extinction differs per channel: the target holds a
                                      * coverage per channel (VOL_TARGET_RGB) */
#define VOL_MAX_VOLUMES 32           /* visible volumes per frame (the host checks) */
#define VOL_FEATURE_LIGHTS 1024      /* physical: local lights (VOL_F_LIGHT_COUNT of them), one pixel per work-item */
#define VOL_FEATURE_SPOT 2048        /* ... some of them spot lights: the cone's factor */
#define VOL_MAX_LIGHTS 32            /* local lights per frame that reach a medium (the host checks) */
/* A light's stretch of a segment is cut into pieces that each subtend at most this angle [rad] at
 * the light (docs/volumetric.md#local-lights): 1 where the light is far, up to 32 where the
 * segment passes it. */
#define VOL_LIGHT_ANGLE_STEP 0.09817477042468103 /* pi / 32 */
#define VOL_LIGHT_MAX_PIECES 32

/* Henyey-Greenstein phase function, normalised over the sphere (1 / 4 pi when g = 0); cos_theta
 * between the ray and the direction toward the light (forward scattering peaks looking at it). */
VOL_FN VOL_REAL vol_phase_hg(VOL_REAL cos_theta, VOL_U g) {
  const VOL_REAL denom = (VOL_REAL)1 + g * g - (VOL_REAL)2 * g * cos_theta;
  return ((VOL_REAL)1 - g * g) / ((VOL_REAL)(4.0 * 3.14159265358979323846) * denom * sqrt(denom));
}

#ifndef VOL_LANE_INSTANCE /* the lanes kernel looks up each lane's shadow with this one */
/* 1 where world point p is lit, 0 in shadow: p is projected by the world -> light clip matrix
 * (column-major) and compared with the map's nearest texel, with the bias toward lit. Points
 * outside the map, behind the light, or over a NaN texel are lit. */
VOL_FN VOL_REAL vol_shadow_lit(VOL_V3 p, VOL_GLOBAL const float* frame, VOL_GLOBAL const float* shadow_map,
                               int reversed_z) {
  VOL_REAL clip[4];
  for (int r = 0; r < 4; ++r)
    clip[r] = VOL_P(frame, VOL_F_SHADOW_MATRIX + r) * p.x + VOL_P(frame, VOL_F_SHADOW_MATRIX + 4 + r) * p.y +
              VOL_P(frame, VOL_F_SHADOW_MATRIX + 8 + r) * p.z + VOL_P(frame, VOL_F_SHADOW_MATRIX + 12 + r);
  if (!(clip[3] > (VOL_REAL)0)) return (VOL_REAL)1;
  const VOL_REAL u = clip[0] / clip[3] * (VOL_REAL)0.5f + (VOL_REAL)0.5f;
  const VOL_REAL v = clip[1] / clip[3] * (VOL_REAL)0.5f + (VOL_REAL)0.5f;
  if (!(u >= (VOL_REAL)0 && u < (VOL_REAL)1 && v >= (VOL_REAL)0 && v < (VOL_REAL)1)) return (VOL_REAL)1;
  const int w = (int)VOL_P(frame, VOL_F_SHADOW_WIDTH), h = (int)VOL_P(frame, VOL_F_SHADOW_HEIGHT);
  const int x = min((int)(u * (VOL_REAL)w), w - 1), y = min((int)(((VOL_REAL)1 - v) * (VOL_REAL)h), h - 1);
  const VOL_REAL map = (VOL_REAL)shadow_map[(size_t)y * (size_t)w + (size_t)x];
  const VOL_REAL z = clip[2] / clip[3], bias = VOL_P(frame, VOL_F_SHADOW_BIAS);
  const int shadowed = reversed_z ? z < map - bias : z > map + bias;
  return shadowed ? (VOL_REAL)0 : (VOL_REAL)1;
}

#endif /* VOL_LANE_INSTANCE */

/* stylized: one volume as the seed's shader draws it, (rgb, alpha) before blending. [front,
 * back] is the ray's part inside the sphere, t_scene the occluder. The march covers
 * min((t_scene - front) * occluder_overshoot, thickness) in `steps` steps from a start offset of
 * -jitter * step * 0.1; the first sample whose noise exceeds 0.1 switches to steps of 0.2 * step
 * after going back 4 of them, and is itself skipped (the seed's adaptive stepping, never back to
 * full steps). Alpha is fog_color.a * saturate(saturate(accumulation / distance) * density).
 * Three parts, so the lanes kernel runs the first two on 16 rays at once: the reach, the steps,
 * the shading. */
VOL_FN VOL_REAL vol_stylized_reach(VOL_REAL front, VOL_REAL back, VOL_REAL t_scene, VOL_U overshoot) {
  const VOL_REAL thickness = back - front;
  return t_scene < (VOL_REAL)INFINITY ? fmin((t_scene - front) * overshoot, thickness) : thickness;
}

/* The steps over [front, front + reach]: the accumulated fog, the shadowed length and the
 * distance marched. The adaptive switch is a per-lane select (the refining sample adds nothing),
 * not a `continue`, so every lane runs the same `steps` iterations. */
VOL_FN void vol_stylized_march(VOL_V3 origin, VOL_V3 dir, VOL_REAL front, VOL_REAL reach, VOL_REAL jitter,
                               VOL_GLOBAL const float* vol, VOL_GLOBAL const float* frame, VOL_NOISE_PARAM,
                               int noise_size, VOL_GLOBAL const float* shadow_map, int steps, int features,
                               VOL_REAL* accumulation, VOL_REAL* shadowed, VOL_REAL* marched) {
  const VOL_REAL step = reach / (VOL_REAL)steps;
  const VOL_U time = VOL_PU(frame, VOL_F_TIME);
  const int noisy = (features & VOL_FEATURE_NOISE) && VOL_PU(vol, VOL_V_NOISE) != (VOL_U)0;
  VOL_REAL m = -jitter * step * (VOL_REAL)VOL_JITTER_SPAN, current = step;
  VOL_REAL acc = (VOL_REAL)0, shade = (VOL_REAL)0;
  VOL_INT refined = !(features & VOL_FEATURE_ADAPTIVE);
  for (int i = 0; i < steps; ++i) {
    m += current;
    const VOL_REAL t = front + m;
    const VOL_V3 p = VOL_MAKE3(origin.x + dir.x * t, origin.y + dir.y * t, origin.z + dir.z * t);
    VOL_REAL fog = noisy ? vol_density_field(vol, p, time, noise, noise_size, features & VOL_FEATURE_DETAIL)
                         : (VOL_REAL)1;
    VOL_INT skip = 0;
    if (features & VOL_FEATURE_ADAPTIVE) {
      skip = !refined && fog > (VOL_REAL)VOL_ADAPTIVE_ONSET;
      if (VOL_ANY(skip)) {
        current = skip ? step * (VOL_REAL)VOL_ADAPTIVE_FACTOR : current;
        m = skip ? m - current * (VOL_REAL)VOL_ADAPTIVE_BACK : m;
        refined = refined || skip;
#ifndef VOL_LANE_INSTANCE
        continue; /* one ray: nothing else to do for this sample */
#endif
      }
    }
    if (features & VOL_FEATURE_FADES) fog *= vol_fades(vol, p, t);
    if (features & VOL_FEATURE_SHADOW) {
      const VOL_REAL lit = vol_shadow_lit(p, frame, shadow_map, features & VOL_FEATURE_SHADOW_REVERSED);
      shade = skip ? shade : shade + ((VOL_REAL)1 - lit) * current;
    }
    acc = skip ? acc : acc + fog * current;
  }
  *accumulation = acc;
  *shadowed = shade;
  *marched = m;
}

#ifndef VOL_LANE_INSTANCE
/* The colour and alpha of a marched volume (marched > 0) seen along dir. */
VOL_FN VOL_V4 vol_stylized_shade(VOL_V3 dir, VOL_REAL accumulation, VOL_REAL shadowed, VOL_REAL marched,
                                 VOL_GLOBAL const float* vol, VOL_GLOBAL const float* frame, int features) {
  /* The lobe toward the light bends colour and light (the seed's k). */
  const VOL_V3 light_dir = VOL_P3(frame, VOL_F_LIGHT_DIR), light = VOL_P3(frame, VOL_F_LIGHT_COLOR);
  const VOL_REAL k = vol_pow(vol_saturate(dot(dir, light_dir)), VOL_P(vol, VOL_V_DIR_FALLOFF));
  const VOL_V3 one = VOL_MAKE3((VOL_REAL)1, (VOL_REAL)1, (VOL_REAL)1);
  const VOL_V3 base_light = one + (light - one) * VOL_P(vol, VOL_V_LIGHT_CONTRIBUTION);
  const VOL_V3 lobe_light = one + (light - one) * VOL_P(vol, VOL_V_DIR_LIGHT_CONTRIBUTION);
  const VOL_V3 light_color = base_light + (lobe_light - base_light) * k;
  const VOL_V4 fog_color = VOL_P4(vol, VOL_V_FOG_COLOR) + (VOL_P4(vol, VOL_V_DIR_FOG_COLOR) - VOL_P4(vol, VOL_V_FOG_COLOR)) * k;
  VOL_REAL total_shadow = (VOL_REAL)1;
  if (features & VOL_FEATURE_SHADOW) {
    const VOL_REAL strength = VOL_P(vol, VOL_V_SHADOW_STRENGTH);
    const VOL_REAL reverse = strength * VOL_P(vol, VOL_V_SHADOW_REVERSE_STRENGTH);
    total_shadow = (VOL_REAL)1 - vol_saturate(shadowed / marched) * (reverse + (strength - reverse) * k);
  }
  const VOL_V3 lit = light_color * total_shadow, floor_light = light_color * (VOL_REAL)VOL_LIGHT_FLOOR;
  const VOL_V3 rgb = VOL_MAKE3(fog_color.x, fog_color.y, fog_color.z) *
                     VOL_MAKE3(fmax(lit.x, floor_light.x), fmax(lit.y, floor_light.y), fmax(lit.z, floor_light.z));
  const VOL_REAL alpha = fog_color.w * vol_saturate(vol_saturate(accumulation / marched) * VOL_P(vol, VOL_V_DENSITY));
  return VOL_MAKE4(rgb.x, rgb.y, rgb.z, alpha);
}

VOL_FN VOL_V4 vol_stylized_volume(VOL_V3 origin, VOL_V3 dir, VOL_REAL front, VOL_REAL back,
                                  VOL_REAL t_scene, VOL_REAL jitter, VOL_GLOBAL const float* vol,
                                  VOL_GLOBAL const float* frame, VOL_NOISE_PARAM, int noise_size,
                                  VOL_GLOBAL const float* shadow_map, int steps, int features) {
  const VOL_REAL reach = vol_stylized_reach(front, back, t_scene, VOL_P(vol, VOL_V_OVERSHOOT));
  if (!(reach > (VOL_REAL)0)) return VOL_MAKE4((VOL_REAL)0, (VOL_REAL)0, (VOL_REAL)0, (VOL_REAL)0);
  VOL_REAL accumulation, shadowed, marched;
  vol_stylized_march(origin, dir, front, reach, jitter, vol, frame, noise, noise_size, shadow_map, steps, features,
                     &accumulation, &shadowed, &marched);
  if (!(marched > (VOL_REAL)0)) return VOL_MAKE4((VOL_REAL)0, (VOL_REAL)0, (VOL_REAL)0, (VOL_REAL)0);
  return vol_stylized_shade(dir, accumulation, shadowed, marched, vol, frame, features);
}

#endif /* VOL_LANE_INSTANCE */

/* The extinction [1/world] and the albedo-weighted light of the volumes of `mask` at p, t:
 * sigma_t = density * field * fades per volume, summed; *source = sum of sigma_t * albedo * L with
 * L = light * phase[i] * shadow + ambient, phase[i] volume i's phase function along the ray (one
 * value per ray: vol_physical_phases). A volume adds where its bit is set (a per-lane select).
 * With VOL_FEATURE_LIGHTS, each[i] is volume i's extinction (0 outside `mask`): the local
 * lights' phase differs per volume and per light. */
VOL_FN VOL_REAL vol_physical_sample(VOL_V3 p, VOL_REAL t, const VOL_REAL* phase, VOL_REAL lit, VOL_UINT mask,
                                    VOL_GLOBAL const float* vols, int count, VOL_GLOBAL const float* frame,
                                    VOL_NOISE_PARAM, int noise_size, int features, VOL_V3* source, VOL_REAL* each) {
  const VOL_U3 light = VOL_PU3(frame, VOL_F_LIGHT_COLOR);
  const VOL_U time = VOL_PU(frame, VOL_F_TIME);
  VOL_REAL sigma_t = (VOL_REAL)0, s_r = (VOL_REAL)0, s_g = (VOL_REAL)0, s_b = (VOL_REAL)0;
  for (int i = 0; i < count; ++i) {
    const VOL_INT in = ((mask >> i) & 1u) != 0u;
    if ((features & VOL_FEATURE_LIGHTS) && !VOL_ANY(in)) each[i] = (VOL_REAL)0;
    if (!VOL_ANY(in)) continue;
    VOL_GLOBAL const float* vol = vols + i * VOL_V_STRIDE;
    VOL_REAL sigma = (VOL_REAL)VOL_PU(vol, VOL_V_DENSITY);
    if ((features & VOL_FEATURE_NOISE) && VOL_PU(vol, VOL_V_NOISE) != (VOL_U)0)
      sigma *= vol_density_field(vol, p, time, noise, noise_size, features & VOL_FEATURE_DETAIL);
    if (features & VOL_FEATURE_FADES) sigma *= vol_fades(vol, p, t);
    const VOL_REAL phase_lit = phase[i] * lit;
    const VOL_U3 albedo = VOL_PU3(vol, VOL_V_ALBEDO), ambient = VOL_PU3(vol, VOL_V_AMBIENT);
    s_r = in ? s_r + albedo.x * (light.x * phase_lit + ambient.x) * sigma : s_r;
    s_g = in ? s_g + albedo.y * (light.y * phase_lit + ambient.y) * sigma : s_g;
    s_b = in ? s_b + albedo.z * (light.z * phase_lit + ambient.z) * sigma : s_b;
    sigma_t = in ? sigma_t + sigma : sigma_t;
    if (features & VOL_FEATURE_LIGHTS) each[i] = in ? sigma : (VOL_REAL)0;
  }
  *source = VOL_MAKE3(s_r, s_g, s_b);
  return sigma_t;
}

/* physical: each volume's phase function along a ray of cos_theta to the light, in phase[0, count)
 * (constant along the ray: computed once, not per sample). */
VOL_FN void vol_physical_phases(VOL_REAL cos_theta, VOL_GLOBAL const float* vols, int count, VOL_REAL* phase) {
  for (int i = 0; i < count; ++i) phase[i] = vol_phase_hg(cos_theta, VOL_PU(vols + i * VOL_V_STRIDE, VOL_V_ANISOTROPY));
}

/* physical: the weight of a segment of length seg with extinction sigma_t > 0 after optical
 * depth `depth`, T * (1 - e^(-sigma_t seg)) / sigma_t; riemann: the textbook T * seg. */
VOL_FN VOL_REAL vol_segment_weight(VOL_REAL sigma_t, VOL_REAL seg, VOL_REAL depth, int riemann) {
  return riemann ? seg * exp(-depth) : -expm1(-sigma_t * seg) * exp(-depth) / sigma_t;
}

/* physical: where segment j of the n of the piece [a, a + length] starts (j = n: the piece's end,
 * which the caller takes as b exactly). j and n are small integers, exact as reals. */
VOL_FN VOL_REAL vol_segment_start(VOL_REAL a, VOL_REAL length, VOL_REAL j, VOL_REAL n) { return a + length * j / n; }

#if !defined(VOL_LANE_INSTANCE) || defined(VOL_LANE_HEIGHT) /* the lanes' with the marched fog only */
/* The marched height fog's segment [ta, tb] of the ray (tb = +inf: the infinite tail), visibility
 * lit, other media's optical depth `other` in it and depth_v in front: fog_height_march_segment per
 * channel, H and H_sun from §6.2's fog_height_length (heights from d0 + s wy, s = t + s_origin).
 * Both instances: the lanes kernel runs it on 16 rays' segments at once. */
VOL_FN void vol_height_segment(VOL_REAL ta, VOL_REAL tb, VOL_REAL s_origin, VOL_REAL wy, VOL_REAL d0,
                               VOL_REAL lit, VOL_REAL other, VOL_REAL depth_v, const VOL_U* hp, int hf,
                               VOL_REAL* dep_ext, VOL_REAL* dep_in, VOL_REAL* dep_sun, VOL_REAL* amb,
                               VOL_REAL* sun) {
  const int falloff = (hf & FOG_HF_FALLOFF) != 0;
  const VOL_INT tail = !(tb < (VOL_REAL)INFINITY);
  const VOL_REAL sa = ta + s_origin, sb = tail ? (VOL_REAL)INFINITY : tb + s_origin;
  const VOL_REAL k = (VOL_REAL)hp[FOG_HP_K];
  const VOL_REAL h = VOL_FOG(fog_height_length)(sa, sb, wy, d0, k, falloff, tail);
  VOL_REAL h_sun = h;
  if (hf & FOG_HF_SUN_START) {
    const VOL_REAL from = fmax(sa, (VOL_REAL)hp[FOG_HP_SUN_START]);
    h_sun = !(tail | (sb > from)) ? (VOL_REAL)0
            : from == sa         ? h
                                 : VOL_FOG(fog_height_length)(from, sb, wy, d0, k, falloff, tail);
  }
  for (int c = 0; c < ((hf & FOG_HF_RGB) ? 3 : 1); ++c)
    VOL_FOG(fog_height_march_segment)(h, h_sun, lit, other, depth_v, hp, c, (hf & FOG_HF_SUN_START) != 0,
                                      &dep_ext[c], &dep_in[c], &dep_sun[c], &amb[c], &sun[c]);
}
#endif

#ifndef VOL_LANE_INSTANCE
/* physical: the piece of the ray that starts at a and ends at the next sphere boundary *b (+inf:
 * none left), and the volumes of `hit` that cover all of it. */
VOL_FN VOL_UINT vol_piece(const VOL_REAL* t_in, const VOL_REAL* t_out, VOL_UINT hit, int count, VOL_REAL a,
                          VOL_REAL* b) {
  VOL_REAL end = (VOL_REAL)INFINITY;
  for (int i = 0; i < count; ++i) {
    if (!((hit >> i) & 1u)) continue;
    if (t_in[i] > a) end = fmin(end, t_in[i]);
    if (t_out[i] > a) end = fmin(end, t_out[i]);
  }
  VOL_UINT mask = 0u;
  for (int i = 0; i < count; ++i)
    if (((hit >> i) & 1u) && t_in[i] <= a && t_out[i] >= end) mask |= 1u << i;
  *b = end;
  return mask;
}

/* physical: the segments of a piece of length `length`, its share of the covered length's steps. */
VOL_FN int vol_piece_segments(VOL_REAL length, int steps, VOL_REAL covered) {
  return max(1, (int)floor(length * (VOL_REAL)steps / covered + (VOL_REAL)0.5f));
}

/* physical: the spheres of the ray, clipped to [0, t_scene]: t_in / t_out of the volumes of the
 * returned bit set, *start the nearest entry. */
VOL_FN VOL_UINT vol_physical_hits(VOL_V3 origin, VOL_V3 dir, VOL_REAL t_scene, VOL_GLOBAL const float* vols, int count,
                                  VOL_REAL* t_in, VOL_REAL* t_out, VOL_REAL* start) {
  VOL_UINT hit = 0u;
  *start = (VOL_REAL)INFINITY;
  for (int i = 0; i < count; ++i) {
    VOL_GLOBAL const float* vol = vols + i * VOL_V_STRIDE;
    VOL_REAL t0, t1;
    if (!vol_sphere_hit(origin, dir, VOL_P3(vol, VOL_V_CENTER), VOL_P(vol, VOL_V_RADIUS), &t0, &t1)) continue;
    t1 = fmin(t1, t_scene);
    if (!(t1 > t0)) continue;
    t_in[i] = t0;
    t_out[i] = t1;
    hit |= 1u << i;
    *start = fmin(*start, t0);
  }
  return hit;
}

/* physical: the length of the ray inside some sphere (the pieces with volumes). */
VOL_FN VOL_REAL vol_covered(const VOL_REAL* t_in, const VOL_REAL* t_out, VOL_UINT hit, int count, VOL_REAL start) {
  VOL_REAL covered = 0, a = start;
  for (int piece = 0; piece < 2 * count; ++piece) {
    VOL_REAL b;
    const VOL_UINT mask = vol_piece(t_in, t_out, hit, count, a, &b);
    if (!(b < (VOL_REAL)INFINITY)) break;
    if (mask != 0u) covered += b - a;
    a = b;
  }
  return covered;
}

#endif /* VOL_LANE_INSTANCE */

/* Local lights (docs/volumetric.md#local-lights), in every instance: the lanes kernel runs them on
 * 16 rays' segments at once. A ray's constants per light, VOL_LR_* in lr (vol_light_rays): the
 * stretch [in, out] of the ray inside the light's range sphere (a lane whose ray misses it: in =
 * +inf, out = 0), the ray parameter t0 of the closest approach, sc = sqrt(h^2 + radius^2) and its
 * reciprocal (h: the ray's distance from the light), h^2, and for spot lights
 * dot(position - origin, axis) and dot(dir, axis). */
#define VOL_LR_IN 0
#define VOL_LR_OUT 1
#define VOL_LR_T0 2
#define VOL_LR_SC 3
#define VOL_LR_INV_SC 4
#define VOL_LR_H2 5
#define VOL_LR_AXIS_AT 6
#define VOL_LR_AXIS_DIR 7
#define VOL_LR_STRIDE 8

/* The lights whose range sphere the ray meets within [t_from, t_scene] (in some lane), once per
 * ray: their indices in ids[0, returned count) and their constants in lr, in that order. A light
 * no ray of the work-item reaches costs nothing after this; a segment outside a light's stretch
 * costs a comparison. t_from <= 0 is where the march starts (the marched height fog starts at
 * the eye, before the ray's origin on the near plane). */
VOL_FN int vol_light_rays(VOL_V3 origin, VOL_V3 dir, VOL_REAL t_from, VOL_REAL t_scene,
                          VOL_GLOBAL const float* lights, int n, int features, VOL_REAL* lr, int* ids) {
  int active = 0;
  for (int k = 0; k < n; ++k) {
    VOL_GLOBAL const float* light = lights + k * VOL_L_STRIDE;
    const VOL_REAL rx = VOL_PU(light, VOL_L_POSITION) - origin.x, ry = VOL_PU(light, VOL_L_POSITION + 1) - origin.y,
                   rz = VOL_PU(light, VOL_L_POSITION + 2) - origin.z;
    const VOL_REAL t0 = rx * dir.x + ry * dir.y + rz * dir.z;
    const VOL_REAL px = rx - dir.x * t0, py = ry - dir.y * t0, pz = rz - dir.z * t0;
    const VOL_REAL h2 = px * px + py * py + pz * pz;
    const VOL_U range = VOL_PU(light, VOL_L_RANGE);
    const VOL_REAL disc = range * range - h2, chord = sqrt(fmax(disc, (VOL_REAL)0));
    const VOL_REAL in = fmax(t0 - chord, t_from), out = fmin(t0 + chord, t_scene);
    const VOL_INT hit = disc > (VOL_REAL)0 && out > in;
    if (!VOL_ANY(hit)) continue;
    VOL_REAL* r = lr + active * VOL_LR_STRIDE;
    const VOL_REAL sc = sqrt(h2 + VOL_PU(light, VOL_L_RADIUS2));
    r[VOL_LR_IN] = hit ? in : (VOL_REAL)INFINITY;
    r[VOL_LR_OUT] = hit ? out : (VOL_REAL)0;
    r[VOL_LR_T0] = t0;
    r[VOL_LR_SC] = sc;
    r[VOL_LR_INV_SC] = (VOL_REAL)1 / sc;
    r[VOL_LR_H2] = h2;
    if (features & VOL_FEATURE_SPOT) {
      const VOL_U ax = VOL_PU(light, VOL_L_AXIS), ay = VOL_PU(light, VOL_L_AXIS + 1), az = VOL_PU(light, VOL_L_AXIS + 2);
      r[VOL_LR_AXIS_AT] = rx * ax + ry * ay + rz * az;
      r[VOL_LR_AXIS_DIR] = dir.x * ax + dir.y * ay + dir.z * az;
    }
    ids[active++] = k;
  }
  return active;
}

/* sigma_s * phase toward the eye of the media at a point lit from cos_theta (between the ray and
 * the direction toward the light), per channel in s[0..2]: each volume of `mask` with its albedo
 * and Henyey-Greenstein g (each[i]: its extinction, 0 outside mask), plus fog_scatter (the marched
 * height fog's scattering coefficient per channel) with the isotropic phase. */
VOL_FN void vol_light_scatter(VOL_REAL cos_theta, const VOL_REAL* each, VOL_UINT mask, VOL_GLOBAL const float* vols,
                              int count, VOL_V3 fog_scatter, VOL_REAL* s) {
  const VOL_REAL iso = (VOL_REAL)(1.0 / (4.0 * 3.14159265358979323846));
  s[0] = fog_scatter.x * iso;
  s[1] = fog_scatter.y * iso;
  s[2] = fog_scatter.z * iso;
  for (int i = 0; i < count; ++i) {
    if (!VOL_ANY(((mask >> i) & 1u) != 0u)) continue;
    VOL_GLOBAL const float* vol = vols + i * VOL_V_STRIDE;
    const VOL_REAL m = each[i] * vol_phase_hg(cos_theta, VOL_PU(vol, VOL_V_ANISOTROPY));
    s[0] += VOL_PU(vol, VOL_V_ALBEDO) * m;
    s[1] += VOL_PU(vol, VOL_V_ALBEDO + 1) * m;
    s[2] += VOL_PU(vol, VOL_V_ALBEDO + 2) * m;
  }
}

/* The mean of e^(-sigma u) over a length of optical thickness `thick`: (1 - e^-thick) / thick. */
VOL_FN VOL_REAL vol_mean_transmittance(VOL_REAL thick) {
  return thick > (VOL_REAL)0 ? -expm1(-thick) / thick : (VOL_REAL)1;
}

/* One piece of a light's stretch of a segment, where `live`: its inverse-square mass (int du /
 * (u^2 + sc^2) over it, exactly: its angle / sc) times its mean transmittance t[0..2] times the
 * scattering, the window and the cone at its midpoint xm (x = u / sc, u = t - t0; r the light's ray
 * constants), added per channel to sum. The distance to the light is taken only where a volume's
 * phase or a cone needs it. */
VOL_FN void vol_light_piece(VOL_REAL xm, VOL_REAL mass, VOL_INT live, const VOL_REAL* r, VOL_GLOBAL const float* light,
                            const VOL_REAL* t, const VOL_REAL* each, VOL_UINT mask, VOL_GLOBAL const float* vols,
                            int count, VOL_V3 fog_scatter, int features, VOL_REAL* sum) {
  const VOL_REAL um = xm * r[VOL_LR_SC];
  const VOL_REAL d2 = um * um + r[VOL_LR_H2];
  const VOL_REAL w = (VOL_REAL)1 - d2 * VOL_PU(light, VOL_L_INV_RANGE2);
  const VOL_INT lit = live && w > (VOL_REAL)0;
  if (!VOL_ANY(lit)) return;
  VOL_REAL weight = w * w * mass, cos_theta = (VOL_REAL)0;
  if (count > 0 || (features & VOL_FEATURE_SPOT)) {
    const VOL_REAL d = sqrt(d2), inv_d = d > (VOL_REAL)0 ? (VOL_REAL)1 / d : (VOL_REAL)0;
    /* toward the light: dot(dir, position - p) = t0 - t = -um */
    cos_theta = -um * inv_d;
    if (features & VOL_FEATURE_SPOT) {
      const VOL_REAL cos_axis =
          d > (VOL_REAL)0 ? ((r[VOL_LR_T0] + um) * r[VOL_LR_AXIS_DIR] - r[VOL_LR_AXIS_AT]) * inv_d : (VOL_REAL)1;
      const VOL_REAL f = vol_saturate(cos_axis * VOL_PU(light, VOL_L_SPOT_SCALE) + VOL_PU(light, VOL_L_SPOT_OFFSET));
      weight = weight * f * f;
    }
  }
  VOL_REAL s[3];
  vol_light_scatter(cos_theta, each, mask, vols, count, fog_scatter, s);
  for (int c = 0; c < 3; ++c) sum[c] = lit ? sum[c] + s[c] * t[c] * weight : sum[c];
}

/* The local lights' in-scattered radiance over the segment [s0, s1] of a ray, extinction sigma_t
 * in it (constant), optical depth `depth` before it, each per channel (`channels` 3: the marched
 * fog's extinction differs per channel; 1: element 0 serves three); the ray's lights from
 * vol_light_rays (lr, ids, n). For each light whose stretch meets the segment, its part [a, b] is
 * cut into pieces of equal angle, at most VOL_LIGHT_ANGLE_STEP, as seen from the light (one, unless
 * the segment passes close to the light). On a piece [ua, ub] (u = t - t0, c = h^2 + radius^2)
 * the inverse square is integrated exactly, int du / (u^2 + c) = (angle subtended) / sqrt(c), and
 * the transmittance exactly by its mean over the piece, T(ua) (1 - e^(-sigma_t (ub - ua))) /
 * (sigma_t (ub - ua)); the window, the cone and the phase are taken at the piece's angular
 * midpoint. A sample at the light or a ray through it is finite: c >= radius^2 > 0.
 * In x = u / sqrt(c) = tan(angle), no angle needs an atan or a tan of its own: the stretch's angle
 * is atan2 of the tangent difference formula (exact, and without the cancellation of two angles
 * near +-pi/2 of a far segment), one piece's midpoint is tan((phi0 + phi1) / 2) by the half-angle
 * identity, and many pieces' ends and midpoints follow by the tangent addition formula from
 * tan(piece angle / 2). */
VOL_FN VOL_V3 vol_lights_segment(VOL_REAL s0, VOL_REAL s1, const VOL_REAL* sigma_t, const VOL_REAL* depth,
                                 int channels, const VOL_REAL* each, VOL_UINT mask, VOL_GLOBAL const float* vols,
                                 int count, VOL_V3 fog_scatter, VOL_GLOBAL const float* lights, const VOL_REAL* lr,
                                 const int* ids, int n, int features) {
  VOL_REAL sum[3] = {(VOL_REAL)0, (VOL_REAL)0, (VOL_REAL)0}, before[3], whole[3];
  int have_whole = 0;
  for (int q = 0; q < n; ++q) {
    const VOL_REAL* r = lr + q * VOL_LR_STRIDE;
    const VOL_REAL a = fmax(s0, r[VOL_LR_IN]), b = fmin(s1, r[VOL_LR_OUT]);
    const VOL_INT on = b > a;
    if (!VOL_ANY(on)) continue; /* the segment is outside the light's range */
    if (!have_whole) { /* T before the segment and its mean over the segment, shared by the lights */
      for (int c = 0; c < channels; ++c) {
        before[c] = exp(-depth[c]);
        whole[c] = before[c] * vol_mean_transmittance(sigma_t[c] * (s1 - s0));
      }
      have_whole = 1;
    }
    VOL_GLOBAL const float* light = lights + ids[q] * VOL_L_STRIDE;
    const VOL_REAL inv_sc = r[VOL_LR_INV_SC];
    const VOL_REAL xa = (a - r[VOL_LR_T0]) * inv_sc, xb = (b - r[VOL_LR_T0]) * inv_sc;
    const VOL_REAL span = on ? atan2((b - a) * inv_sc, (VOL_REAL)1 + xa * xb) : (VOL_REAL)0;
    const VOL_REAL pieces = fmin((VOL_REAL)VOL_LIGHT_MAX_PIECES,
                                 fmax((VOL_REAL)1, ceil(span / (VOL_REAL)VOL_LIGHT_ANGLE_STEP)));
    /* T at a, e^(-sigma_t (a - s0)) after `before`: 1 unless the stretch starts inside the segment */
    VOL_REAL t[3] = {(VOL_REAL)0, (VOL_REAL)0, (VOL_REAL)0}, at_a[3];
    const VOL_INT late = on && a > s0;
    for (int c = 0; c < channels; ++c)
      at_a[c] = VOL_ANY(late) ? (late ? before[c] * exp(-sigma_t[c] * (a - s0)) : before[c]) : before[c];
    VOL_REAL light_sum[3] = {(VOL_REAL)0, (VOL_REAL)0, (VOL_REAL)0};
    if (VOL_ANY(on && pieces > (VOL_REAL)1)) {
      /* pieces of angle `piece`: from x0 = tan(phi), the end tan(phi + piece) = (x0 + k) / (1 - x0 k)
       * and the midpoint (x0 + k2) / (1 - x0 k2), k = tan(piece), k2 = tan(piece / 2); both kept
       * within the stretch. The transmittance at each piece's start carries over. */
      const VOL_REAL piece = span / pieces, k2 = tan(piece * (VOL_REAL)0.5f);
      const VOL_REAL k = (VOL_REAL)2 * k2 / ((VOL_REAL)1 - k2 * k2), sc = r[VOL_LR_SC];
      VOL_REAL x1 = xa;
      for (int j = 0; j < VOL_LIGHT_MAX_PIECES && VOL_ANY(on && (VOL_REAL)j < pieces); ++j) {
        const VOL_INT live = on && (VOL_REAL)j < pieces;
        const VOL_REAL x0 = x1;
        x1 = (VOL_REAL)(j + 1) >= pieces ? xb : fmin(fmax((x0 + k) / ((VOL_REAL)1 - x0 * k), x0), xb);
        const VOL_REAL xm = fmin(fmax((x0 + k2) / ((VOL_REAL)1 - x0 * k2), x0), x1);
        const VOL_REAL len = (x1 - x0) * sc;
        for (int c = 0; c < channels; ++c) {
          const VOL_REAL thick = sigma_t[c] * len, fall = -expm1(-thick); /* 1 - e^-thick */
          t[c] = at_a[c] * (thick > (VOL_REAL)0 ? fall / thick : (VOL_REAL)1);
          at_a[c] = live ? at_a[c] - at_a[c] * fall : at_a[c];
        }
        if (channels == 1) t[1] = t[2] = t[0];
        vol_light_piece(xm, piece * inv_sc, live, r, light, t, each, mask, vols, count, fog_scatter, features,
                        light_sum);
      }
    } else {
      /* one piece: tan((phi_a + phi_b) / 2) = (sin phi_a + sin phi_b) / (cos phi_a + cos phi_b) */
      const VOL_REAL ra = sqrt((VOL_REAL)1 + xa * xa), rb = sqrt((VOL_REAL)1 + xb * xb);
      const VOL_REAL xm = (xa * rb + xb * ra) / (ra + rb);
      const VOL_INT whole_piece = !late && b == s1;
      for (int c = 0; c < channels; ++c)
        t[c] = VOL_ANY(on && !whole_piece)
                   ? (whole_piece ? whole[c] : at_a[c] * vol_mean_transmittance(sigma_t[c] * (b - a)))
                   : whole[c];
      if (channels == 1) t[1] = t[2] = t[0];
      vol_light_piece(xm, span * inv_sc, on, r, light, t, each, mask, vols, count, fog_scatter, features,
                      light_sum);
    }
    sum[0] += VOL_PU(light, VOL_L_RADIANCE) * light_sum[0];
    sum[1] += VOL_PU(light, VOL_L_RADIANCE + 1) * light_sum[1];
    sum[2] += VOL_PU(light, VOL_L_RADIANCE + 2) * light_sum[2];
  }
  return VOL_MAKE3(sum[0], sum[1], sum[2]);
}

/* The local lights of one segment of the march [s0, s1] (vol_physical's and the lanes'): the
 * extinction there is the volumes' sigma_t (where > 0) plus, where `fogged`, the marched fog's
 * added optical depth over the segment per unit length (fog_ext - ext_before, per channel), and
 * the fog scatters its in-scattering depth per unit length (fog_in - in_before; channel 0 serves
 * three where fog_rgb is 0); the optical depth in front is the volumes' depth plus ext_before. */
VOL_FN VOL_V3 vol_segment_lights(VOL_REAL s0, VOL_REAL s1, VOL_REAL sigma_t, VOL_REAL depth, VOL_INT fogged,
                                 const VOL_REAL* ext_before, const VOL_REAL* fog_ext, const VOL_REAL* in_before,
                                 const VOL_REAL* fog_in, int fog_rgb, int channels, const VOL_REAL* each,
                                 VOL_UINT mask, VOL_GLOBAL const float* vols, int count,
                                 VOL_GLOBAL const float* lights, const VOL_REAL* lr, const int* ids, int n,
                                 int features) {
  const VOL_REAL seg = s1 - s0;
  const VOL_INT thick = fogged && seg > (VOL_REAL)0;
  VOL_REAL fog_s[3], sigma_all[3], depth_all[3];
  for (int c = 0; c < 3; ++c) {
    const int f = fog_rgb ? c : 0;
    fog_s[c] = thick ? (fog_in[f] - in_before[f]) / seg : (VOL_REAL)0;
  }
  for (int c = 0; c < channels; ++c) {
    sigma_all[c] = (sigma_t > (VOL_REAL)0 ? sigma_t : (VOL_REAL)0) +
                   (thick ? (fog_ext[c] - ext_before[c]) / seg : (VOL_REAL)0);
    depth_all[c] = depth + ext_before[c];
  }
  return vol_lights_segment(s0, s1, sigma_all, depth_all, channels, each, mask, vols, count,
                            VOL_MAKE3(fog_s[0], fog_s[1], fog_s[2]), lights, lr, ids, n, features);
}

#ifndef VOL_LANE_INSTANCE

/* The marched height fog's stretch of a ray (docs/DESIGN.md §6.5): §6.2's [s0, s1] in distance
 * from the eye (the view plane), as ray parameters [*t0, *t1] (t = s - s_origin, s_origin the
 * ray origin's distance). An infinite ray (a fogged sky without cut-off) marches to `reach` (or
 * s0) and sets *infinite: the closed form's tail [*t1, inf) follows. Returns 0 where the ray has
 * no fog (sky unfogged, empty stretch). */
VOL_FN int vol_height_stretch(VOL_REAL t_scene, VOL_REAL s_origin, VOL_REAL reach, const VOL_U* hp, int hf,
                              VOL_REAL* t0, VOL_REAL* t1, int* infinite) {
  const VOL_REAL s0 = (hf & FOG_HF_START) ? (VOL_REAL)hp[FOG_HP_START] : (VOL_REAL)0;
  VOL_REAL s1;
  *infinite = 0;
  if (!(t_scene < (VOL_REAL)INFINITY)) {
    if (!(hf & FOG_HF_SKYBOX)) return 0;
    if (hf & FOG_HF_CUTOFF) {
      s1 = (VOL_REAL)hp[FOG_HP_CUTOFF];
    } else {
      *infinite = 1;
      s1 = fmax(reach, s0);
    }
  } else {
    s1 = t_scene + s_origin;
    if (hf & FOG_HF_CUTOFF) s1 = fmin(s1, (VOL_REAL)hp[FOG_HP_CUTOFF]);
  }
  if (!*infinite && !(s1 > s0)) return 0;
  *t0 = s0 - s_origin;
  *t1 = s1 - s_origin;
  return 1;
}

/* The marched height fog's part of a ray (docs/DESIGN.md §6.5): the ray origin's distance
 * *s_origin, its height above the base *d0, and the fog's stretch added to the ray's pieces as
 * volume `count` (t_in, t_out, *hit, *start), where it has one; an infinite ray (*infinite) ends
 * with the closed form's tail from *tail_from, behind every volume. */
VOL_FN void vol_height_ray(VOL_V3 origin, VOL_V3 dir, VOL_REAL t_scene, VOL_REAL t_per_eye,
                           VOL_GLOBAL const float* frame, const VOL_U* hp, int hf, int count, VOL_REAL* t_in,
                           VOL_REAL* t_out, VOL_UINT* hit, VOL_REAL* start, VOL_REAL* s_origin, VOL_REAL* d0,
                           VOL_REAL* tail_from, int* infinite) {
  *s_origin = VOL_P(frame, VOL_F_NEAR) * t_per_eye;
  *d0 = origin.y - *s_origin * dir.y - VOL_P(frame, VOL_F_HEIGHT_BASE);
  *tail_from = (VOL_REAL)0;
  *infinite = 0;
  VOL_REAL f0, f1;
  if (!vol_height_stretch(t_scene, *s_origin, VOL_P(frame, VOL_F_HEIGHT_REACH) * t_per_eye, hp, hf, &f0, &f1,
                          infinite))
    return;
  if (*infinite)
    for (int i = 0; i < count; ++i)
      if ((*hit >> i) & 1u) f1 = fmax(f1, t_out[i]); /* the tail starts behind every volume */
  *tail_from = f1;
  if (f1 > f0) {
    t_in[count] = f0;
    t_out[count] = f1;
    *hit |= 1u << count;
    *start = fmin(*start, f0);
  }
}

/* The marched height fog's end of a ray (docs/DESIGN.md §6.5): an infinite ray's tail [tail_from,
 * inf) as one more segment (visibility at its start), then P += F·ambient + S·λ·sun onto i (the
 * volumes' light) and the coverage 1 - e^(-(volumes' depth + the fog's β_ext·H)) per channel in
 * coverage[0..2] (one value where the extinction is grey); returns (P, coverage[0]). The sums are
 * the fog's per-channel state of vol_physical (channel 0 alone where FOG_HF_RGB is off). */
VOL_FN VOL_V4 vol_height_finish(VOL_V3 origin, VOL_V3 dir, VOL_REAL tail_from, int infinite, VOL_REAL s_origin,
                                VOL_REAL d0, VOL_REAL depth, VOL_V3 i, const VOL_U* hp, int hf,
                                VOL_GLOBAL const float* frame, VOL_GLOBAL const float* shadow_map, int features,
                                VOL_REAL* fog_ext, VOL_REAL* fog_in, VOL_REAL* fog_sun_depth, VOL_REAL* fog_amb,
                                VOL_REAL* fog_sun, VOL_REAL* coverage) {
  if (infinite) {
    const VOL_V3 p = origin + dir * tail_from;
    const VOL_REAL lit = (features & VOL_FEATURE_SHADOW)
                             ? vol_shadow_lit(p, frame, shadow_map, features & VOL_FEATURE_SHADOW_REVERSED)
                             : (VOL_REAL)1;
    vol_height_segment(tail_from, (VOL_REAL)INFINITY, s_origin, dir.y, d0, lit, (VOL_REAL)0, depth, hp, hf, fog_ext,
                       fog_in, fog_sun_depth, fog_amb, fog_sun);
  }
  if (!(hf & FOG_HF_RGB)) {
    fog_ext[1] = fog_ext[2] = fog_ext[0];
    fog_amb[1] = fog_amb[2] = fog_amb[0];
    fog_sun[1] = fog_sun[2] = fog_sun[0];
  }
  VOL_REAL lobe = (VOL_REAL)0;
  if (hf & FOG_HF_SUN) {
    const VOL_V3 l = VOL_P3(frame, VOL_F_HEIGHT_SUN);
    lobe = fog_sun_lobe(fog_sun_q(dir.x, dir.y, dir.z, l.x, l.y, l.z), (VOL_REAL)hp[FOG_HP_SUN_EXP]);
  }
  VOL_REAL p[3] = {i.x, i.y, i.z};
  for (int c = 0; c < 3; ++c) {
    p[c] += (VOL_REAL)hp[FOG_HP_FOG + c] * fog_amb[c] +
            ((hf & FOG_HF_SUN) ? (VOL_REAL)hp[FOG_HP_SUN + c] * lobe * fog_sun[c] : (VOL_REAL)0);
    coverage[c] = -expm1(-(depth + fog_ext[c]));
  }
  return VOL_MAKE4(p[0], p[1], p[2], coverage[0]);
}

/* physical (Hillaire 2015, "Physically Based and Unified Volumetric Rendering in Frostbite"):
 * all volumes of the ray at once, returns (in-scattered I, premultiplied; coverage 1 - T), and the
 * coverage per channel in coverage[0..2] (the marched fog's extinction may differ per channel).
 * The ray's covered stretch is cut at every sphere boundary into pieces where the same volumes
 * overlap; the steps are shared out in proportion to length (at least one per piece), so the
 * segments tile each sphere's chord [front, min(back, t_scene)] exactly. Per segment of length
 * d with extinction sigma_t sampled inside it (jitter: where; unjittered: the midpoint):
 * I += T * (source / sigma_t) * (1 - e^(-sigma_t d)), optical depth += sigma_t d. Exact for
 * piecewise-constant media at any d: with albedo 1 and unit light, I + T = 1 to rounding. The
 * (1 - e^x) is -expm1, so thin media keep their digits, and nothing divides by sigma_t but the
 * sigma_t-weighted mean source / sigma_t of the volumes' albedo * L, taken only where sigma_t > 0
 * (the textbook (S - S e^(-sigma_t d)) / sigma_t form is 0 / 0 in clear air).
 * riemann != 0 (VOL_RIEMANN, for comparison only: fogcl report --volumetric, the stiffness test)
 * replaces the segment's exact weight by the textbook left Riemann sum I += T * source * d with T
 * at the segment's start: not energy-conserving, it overshoots by up to sigma_t d when
 * sigma_t d >> 1. The lanes kernel walks the same pieces and segments per lane. */
VOL_FN VOL_V4 vol_physical(VOL_V3 origin, VOL_V3 dir, VOL_REAL t_scene, VOL_REAL t_per_eye, VOL_REAL jitter,
                           VOL_GLOBAL const float* vols, int count, VOL_GLOBAL const float* frame,
                           VOL_NOISE_PARAM, int noise_size, VOL_GLOBAL const float* shadow_map,
                           int steps, int features, int height_features, int riemann, VOL_REAL* coverage) {
  VOL_REAL t_in[VOL_MAX_VOLUMES], t_out[VOL_MAX_VOLUMES], start;
  VOL_UINT hit = vol_physical_hits(origin, dir, t_scene, vols, count, t_in, t_out, &start);
  VOL_REAL i_r = 0, i_g = 0, i_b = 0, depth = 0;
  /* The marched height fog (docs/DESIGN.md §6.5) walks as one more volume, bit `count`, over its
   * stretch [t_in, t_out]; an infinite ray ends with the closed form's tail. */
  const int height = (features & VOL_FEATURE_HEIGHT) != 0, hf = height_features;
  const VOL_UINT fog_bit = height ? 1u << count : 0u;
  const int walked = height ? count + 1 : count;
  VOL_U hp[FOG_HP_COUNT];
  VOL_REAL fog_ext[3] = {0, 0, 0}, fog_in[3] = {0, 0, 0}, fog_sun_depth[3] = {0, 0, 0};
  VOL_REAL fog_amb[3] = {0, 0, 0}, fog_sun[3] = {0, 0, 0};
  VOL_REAL s_origin = 0, wy = 0, d0 = 0, tail_from = 0;
  int infinite = 0;
  if (height) {
    for (int k = 0; k < FOG_HP_COUNT; ++k) hp[k] = VOL_PU(frame, VOL_F_HEIGHT_P + k);
    vol_height_ray(origin, dir, t_scene, t_per_eye, frame, hp, hf, count, t_in, t_out, &hit, &start, &s_origin, &d0,
                   &tail_from, &infinite);
    wy = dir.y;
  }
  coverage[0] = coverage[1] = coverage[2] = (VOL_REAL)0;
  if (hit == 0u && !infinite) return VOL_MAKE4((VOL_REAL)0, (VOL_REAL)0, (VOL_REAL)0, (VOL_REAL)0);
  /* Local lights: their spans along the ray once; each[] the volumes' extinctions of a segment. */
  const int n_lights = (features & VOL_FEATURE_LIGHTS) ? (int)VOL_P(frame, VOL_F_LIGHT_COUNT) : 0;
  VOL_GLOBAL const float* lights = vols + ((features & VOL_FEATURE_LIGHTS) ? (int)VOL_P(frame, VOL_F_LIGHT_OFFSET) : 0);
  VOL_REAL lr[VOL_MAX_LIGHTS * VOL_LR_STRIDE], each[VOL_MAX_VOLUMES];
  int light_ids[VOL_MAX_LIGHTS];
  const int ray_lights = n_lights > 0 ? vol_light_rays(origin, dir, fmin(start, (VOL_REAL)0), t_scene, lights,
                                                       n_lights, features, lr, light_ids)
                                     : 0;
  /* The fog's extinction per channel (VOL_FEATURE_HEIGHT_RGB) dims the volumes' light per channel. */
  const int channels = (features & VOL_FEATURE_HEIGHT_RGB) ? 3 : 1;
  VOL_REAL phase[VOL_MAX_VOLUMES];
  vol_physical_phases(dot(dir, VOL_P3(frame, VOL_F_LIGHT_DIR)), vols, count, phase);
  const VOL_REAL covered = hit != 0u ? vol_covered(t_in, t_out, hit, walked, start) : (VOL_REAL)0;
  VOL_REAL a = start;
  for (int piece = 0; hit != 0u && piece < 2 * walked; ++piece) {
    VOL_REAL b;
    const VOL_UINT mask = vol_piece(t_in, t_out, hit, walked, a, &b);
    if (!(b < (VOL_REAL)INFINITY)) break;
    if (mask != 0u) {
      const VOL_REAL length_ab = b - a;
      const int n = vol_piece_segments(length_ab, steps, covered);
      VOL_REAL s1 = a; /* segment j starts where segment j - 1 ends (j = 0: vol_segment_start's a) */
      for (int j = 0; j < n; ++j) {
        const VOL_REAL s0 = s1;
        s1 = j + 1 == n ? b : vol_segment_start(a, length_ab, (VOL_REAL)(j + 1), (VOL_REAL)n);
        const VOL_REAL seg = s1 - s0, t = s0 + jitter * seg;
        const VOL_V3 p = origin + dir * t;
        const VOL_REAL lit = (features & VOL_FEATURE_SHADOW)
                                 ? vol_shadow_lit(p, frame, shadow_map, features & VOL_FEATURE_SHADOW_REVERSED)
                                 : (VOL_REAL)1;
        VOL_V3 source;
        const VOL_REAL sigma_t = vol_physical_sample(p, t, phase, lit, mask, vols, count, frame, noise,
                                                     noise_size, features, &source, each);
        /* The marched fog's segment (§6.5), where the segment has the fog: extinctions add, the
         * volumes' light shares the segment with the fog's. ext_before, in_before: the fog's sums
         * in front of the segment (its sums as they are where it has none). */
        const int fogged = height && (mask & fog_bit);
        const VOL_REAL ext_before[3] = {fog_ext[0], fog_ext[1], fog_ext[2]};
        const VOL_REAL in_before[3] = {fog_in[0], fog_in[1], fog_in[2]};
        if (fogged)
          vol_height_segment(s0, s1, s_origin, wy, d0, lit, sigma_t > (VOL_REAL)0 ? sigma_t * seg : (VOL_REAL)0, depth,
                             hp, hf, fog_ext, fog_in, fog_sun_depth, fog_amb, fog_sun);
        if (ray_lights > 0 && (sigma_t > (VOL_REAL)0 || (fogged && seg > (VOL_REAL)0))) {
          const VOL_V3 l = vol_segment_lights(s0, s1, sigma_t, depth, fogged, ext_before, fog_ext, in_before, fog_in,
                                              (hf & FOG_HF_RGB) != 0, channels, each, mask, vols, count, lights, lr,
                                              light_ids, ray_lights, features);
          i_r += l.x;
          i_g += l.y;
          i_b += l.z;
        }
        if (!(sigma_t > (VOL_REAL)0)) continue;
        VOL_REAL scatter[3];
        for (int c = 0; c < channels; ++c)
          scatter[c] = vol_segment_weight(fogged ? sigma_t + (fog_ext[c] - ext_before[c]) / seg : sigma_t, seg,
                                          depth + ext_before[c], riemann);
        if (channels == 1) scatter[1] = scatter[2] = scatter[0];
        i_r += source.x * scatter[0];
        i_g += source.y * scatter[1];
        i_b += source.z * scatter[2];
        depth += sigma_t * seg;
      }
    }
    a = b;
  }
  if (!height) {
    coverage[0] = coverage[1] = coverage[2] = -expm1(-depth);
    return VOL_MAKE4(i_r, i_g, i_b, coverage[0]);
  }
  return vol_height_finish(origin, dir, tail_from, infinite, s_origin, d0, depth, VOL_MAKE3(i_r, i_g, i_b), hp, hf,
                           frame, shadow_map, features, fog_ext, fog_in, fog_sun_depth, fog_amb, fog_sun, coverage);
}

/* The target pixel (lx, ly) as the march sees it: its ray, the distance along it to the occluder,
 * the distance per unit of eye depth (vol_pixel_ray) and the block's eye depth in *key for the
 * upsampling. */
VOL_FN void vol_pixel_view(int lx, int ly, VOL_GLOBAL const float* depth_buffer, VOL_GLOBAL const float* frame,
                           int projection, int reversed_z, int kind, VOL_V3* origin, VOL_V3* dir, VOL_REAL* t_scene,
                           VOL_REAL* t_per_eye, VOL_REAL* key) {
  const int scale = (int)VOL_P(frame, VOL_F_SCALE);
  const VOL_REAL near_plane = VOL_P(frame, VOL_F_NEAR);
  const VOL_REAL eye_depth = vol_block_eye_depth(depth_buffer, lx, ly, scale, (int)VOL_P(frame, VOL_F_WIDTH),
                                                 (int)VOL_P(frame, VOL_F_HEIGHT), projection, reversed_z, kind,
                                                 VOL_P(frame, VOL_F_ZX), VOL_P(frame, VOL_F_ZY), near_plane,
                                                 VOL_P(frame, VOL_F_FAR));
  *key = eye_depth;
  const VOL_REAL block_centre = (VOL_REAL)scale * (VOL_REAL)0.5f;
  vol_pixel_ray((VOL_REAL)(lx * scale) + block_centre, (VOL_REAL)(ly * scale) + block_centre, frame, projection, origin,
                dir, t_per_eye);
  *t_scene = vol_scene_distance(eye_depth, near_plane, *t_per_eye);
}

/* stylized: the volume's (rgb, alpha) c drawn over the target with the seed's blend (SrcAlpha,
 * OneMinusSrcAlpha; One, OneMinusSrcAlpha): premultiplied colour and coverage. */
VOL_FN VOL_V4 vol_over(VOL_V4 target, VOL_V4 c) {
  const VOL_REAL keep = (VOL_REAL)1 - c.w;
  return VOL_MAKE4(c.x * c.w + target.x * keep, c.y * c.w + target.y * keep, c.z * c.w + target.z * keep,
                   c.w + target.w * keep);
}

/* The target pixel (lx, ly): its ray, its occluder, the march of the chosen integrator. Returns
 * (P premultiplied RGB, coverage A), the coverage per channel in coverage[0..2] (vol_physical) and
 * the block's eye depth in *key for the upsampling. */
VOL_FN VOL_V4 vol_march_pixel(int lx, int ly, VOL_GLOBAL const float* depth_buffer, VOL_GLOBAL const float* frame,
                              VOL_GLOBAL const float* vols, int count, VOL_NOISE_PARAM, int noise_size,
                              VOL_GLOBAL const float* shadow_map, VOL_UINT frame_index, int integrator, int steps,
                              int features, int height_features, int jitter, int projection, int reversed_z, int kind,
                              VOL_REAL* key, VOL_REAL* coverage) {
  VOL_V3 origin, dir;
  VOL_REAL t_scene, t_per_eye;
  vol_pixel_view(lx, ly, depth_buffer, frame, projection, reversed_z, kind, &origin, &dir, &t_scene, &t_per_eye, key);
  const float j = vol_jitter((VOL_UINT)lx, (VOL_UINT)ly, frame_index);
  if (integrator != VOL_STYLIZED)
    return vol_physical(origin, dir, t_scene, t_per_eye, jitter ? (VOL_REAL)j : (VOL_REAL)0.5f, vols, count, frame,
                        noise, noise_size, shadow_map, steps, features, height_features, integrator == VOL_RIEMANN,
                        coverage);
  /* stylized: each volume drawn over the target in the order given. */
  VOL_V4 target = VOL_MAKE4((VOL_REAL)0, (VOL_REAL)0, (VOL_REAL)0, (VOL_REAL)0);
  for (int i = 0; i < count; ++i) {
    VOL_GLOBAL const float* vol = vols + i * VOL_V_STRIDE;
    VOL_REAL t0, t1;
    if (!vol_sphere_hit(origin, dir, VOL_P3(vol, VOL_V_CENTER), VOL_P(vol, VOL_V_RADIUS), &t0, &t1)) continue;
    if (!(t0 < t_scene)) continue;
    target = vol_over(target, vol_stylized_volume(origin, dir, t0, t1, t_scene, jitter ? (VOL_REAL)j : (VOL_REAL)0, vol,
                                                  frame, noise, noise_size, shadow_map, steps, features));
  }
  coverage[0] = coverage[1] = coverage[2] = target.w;
  return target;
}
#endif /* VOL_LANE_INSTANCE */
