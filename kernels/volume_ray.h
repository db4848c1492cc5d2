/* volume_ray.h — rays and what they hit (docs/volumetric.md §World and rays): the ray of a
 * target pixel, the distance along it to the depth buffer's surface, the intersection with a
 * fog sphere. Needs volume_common.h and fog_math.h's scalar instance (depth linearisation). */

/* Projections, as fog_math.h numbers them (FOG_PROJECTION_*). */

/* Eye depth (view z) of a depth sample, +inf for sky (docs/DESIGN.md §2's sky test; raw 0 with an
 * infinite far plane). NaN and out-of-range depths are sanitised as in the deferred pass. kind:
 * FOG_DEPTH_RAW, or FOG_DEPTH_EYE for linear eye depth, read as it is (fog_clamp_linear_depth; the
 * host turns radial distance into eye depth for this pass). */
VOL_FN VOL_REAL vol_eye_depth(VOL_REAL raw, int projection, int reversed_z, int kind, VOL_REAL zx, VOL_REAL zy,
                              VOL_REAL near_plane, VOL_REAL far_plane) {
  if (kind != FOG_DEPTH_RAW) {
    int sky;
    const VOL_REAL eye = fog_clamp_linear_depth(raw, near_plane, far_plane, &sky);
    return sky ? (VOL_REAL)INFINITY : eye;
  }
  const VOL_REAL depth = fog_sanitize_depth(raw, reversed_z);
  if (projection == FOG_PROJECTION_INFINITE_FAR)
    return depth == (VOL_REAL)0 ? (VOL_REAL)INFINITY : fog_eye_depth_infinite(depth, near_plane);
  const VOL_REAL linear01 = projection == FOG_PROJECTION_ORTHOGRAPHIC
                                ? fog_linear01_depth_ortho(depth, zx, zy)
                                : fog_linear01_depth(depth, zx, zy, reversed_z);
  return fog_is_sky(linear01) ? (VOL_REAL)INFINITY : linear01 * far_plane;
}

/* The nearest eye depth of the s x s block of full-resolution pixels a target pixel covers
 * (clipped to the frame): the target marches to the nearest surface of its block, and the
 * depth-aware upsampling gives the block's farther pixels the fog of neighbours that match them. */
VOL_FN VOL_REAL vol_block_eye_depth(VOL_GLOBAL const float* depth, int lx, int ly, int scale, int width,
                                    int height, int projection, int reversed_z, int kind, VOL_REAL zx, VOL_REAL zy,
                                    VOL_REAL near_plane, VOL_REAL far_plane) {
  VOL_REAL nearest = (VOL_REAL)INFINITY;
  const int x1 = min(lx * scale + scale, width), y1 = min(ly * scale + scale, height);
  for (int y = ly * scale; y < y1; ++y)
    for (int x = lx * scale; x < x1; ++x)
      nearest = fmin(nearest, vol_eye_depth((VOL_REAL)depth[(size_t)y * (size_t)width + (size_t)x],
                                            projection, reversed_z, kind, zx, zy, near_plane, far_plane));
  return nearest;
}

/* A target pixel's ray. Its centre is the centre of its s x s block of the frame; the corner
 * rays interpolate there as in the deferred pass (fog_bilerp) and turn into world space by the
 * camera's rotation. Perspective: the ray starts on the near plane and points along the corner
 * ray (the seed's fix for uv-built directions); *t_per_eye converts eye depth beyond the near
 * plane into distance along the ray, |c| / c.z. Orthographic: it starts at the pixel's point of
 * the near plane and points forward; distance is eye depth - near. */
VOL_FN void vol_pixel_ray(VOL_REAL px, VOL_REAL py, VOL_GLOBAL const float* frame, int projection,
                          VOL_V3* origin, VOL_V3* dir, VOL_REAL* t_per_eye) {
  const VOL_REAL u = px / VOL_P(frame, VOL_F_WIDTH), v = (VOL_REAL)1 - py / VOL_P(frame, VOL_F_HEIGHT);
  VOL_REAL c[3];
  for (int k = 0; k < 3; ++k)
    c[k] = fog_bilerp(VOL_P(frame, VOL_F_CORNERS + k), VOL_P(frame, VOL_F_CORNERS + 3 + k),
                      VOL_P(frame, VOL_F_CORNERS + 6 + k), VOL_P(frame, VOL_F_CORNERS + 9 + k), u, v);
  const VOL_V3 right = VOL_P3(frame, VOL_F_RIGHT), up = VOL_P3(frame, VOL_F_UP);
  const VOL_V3 forward = VOL_P3(frame, VOL_F_FORWARD), eye = VOL_P3(frame, VOL_F_EYE);
  const VOL_REAL near_plane = VOL_P(frame, VOL_F_NEAR), corner_z = VOL_P(frame, VOL_F_CORNER_Z);
  if (projection == FOG_PROJECTION_ORTHOGRAPHIC) {
    *origin = eye + right * c[0] + up * c[1] + forward * near_plane;
    *dir = forward;
    *t_per_eye = (VOL_REAL)1;
    return;
  }
  const VOL_V3 world = right * c[0] + up * c[1] + forward * c[2];
  *origin = eye + world * (near_plane / corner_z);
  *dir = normalize(world);
  *t_per_eye = length(VOL_MAKE3(c[0], c[1], c[2])) / corner_z;
}

/* Distance along the ray from its origin to the depth buffer's surface (docs/volumetric.md §World and rays): exact,
 * where the seed compares with lerp(near, far, Linear01Depth), off by the ray's angle. */
VOL_FN VOL_REAL vol_scene_distance(VOL_REAL eye_depth, VOL_REAL near_plane, VOL_REAL t_per_eye) {
  if (!(eye_depth < (VOL_REAL)INFINITY)) return (VOL_REAL)INFINITY;
  return fmax(eye_depth - near_plane, (VOL_REAL)0) * t_per_eye;
}

/* Ray (unit dir) against the sphere (center, radius): returns 0 on a miss, else 1 with
 * [*t0, *t1] the part of the ray inside, t0 >= 0 (the camera inside gives t0 = 0). The chord is
 * found from the perpendicular distance and the smaller root from the product of the roots, so
 * neither cancels (Haines et al., "Precision Improvements for Ray/Sphere Intersection", Ray
 * Tracing Gems, 2019). */
VOL_FN int vol_sphere_hit(VOL_V3 origin, VOL_V3 dir, VOL_V3 center, VOL_REAL radius, VOL_REAL* t0, VOL_REAL* t1) {
  const VOL_V3 f = origin - center;
  const VOL_REAL b = dot(f, dir);
  const VOL_V3 perp = f - dir * b;
  const VOL_REAL disc = radius * radius - dot(perp, perp);
  if (!(disc >= (VOL_REAL)0)) return 0;
  const VOL_REAL h = sqrt(disc);
  const VOL_REAL len = length(f);
  const VOL_REAL c = (len - radius) * (len + radius); /* t_near * t_far */
  if (b > (VOL_REAL)0 && c > (VOL_REAL)0) return 0; /* the sphere lies behind the origin */
  const VOL_REAL q = b > (VOL_REAL)0 ? -b - h : -b + h;
  VOL_REAL a0 = c / q, a1 = q;
  if (b > (VOL_REAL)0) { const VOL_REAL s = a0; a0 = a1; a1 = s; }
  if (q == (VOL_REAL)0) { a0 = -h; a1 = h; }
  if (!(a1 > (VOL_REAL)0)) return 0;
  *t0 = fmax(a0, (VOL_REAL)0);
  *t1 = a1;
  return 1;
}
