/* volume_common.h — what every header of the volumetric pass shares (docs/volumetric.md): the
 * language bridge and the layouts of the two parameter arrays the host packs.
 *
 * The volume headers are written once and compiled two ways, like fog_math.h:
 *   - OpenCL C, one pixel per work-item: VOL_REAL float, VOL_V3 float3, VOL_V4 float4;
 *   - C++ (src/volume/): every function a template on VOL_REAL (float for the scalar baseline,
 *     double for the reference), VOL_V3 glm::vec<3, VOL_REAL>.
 * Only operations both languages have appear: + - * / on reals and vectors, dot, length,
 * normalize, sqrt, exp, expm1, pow, floor, fmin, fmax, fabs, and the hooks below.
 * VOL_T(f) names a function whose real type cannot be deduced from its arguments.
 *
 * A third instance, OpenCL C on 16 pixels (volume_march.cl with VOL_LANES 16, CPU devices,
 * docs/volumetric.md §Lanes on CPU devices), compiles the per-sample functions again with
 * VOL_REAL float16 (one lane per target pixel), VOL_V3 / VOL_V4 structs of float16 and
 * VOL_LANE_INSTANCE defined. Those functions are written so that all three instances read the
 * same: vectors by component, a parameter of the frame or a volume as a uniform VOL_U (float in
 * OpenCL C; VOL_REAL in C++), every per-lane decision as ?: on a comparison (a per-lane select
 * on vectors), VOL_ANY(m) to skip work no lane needs, and VOL_INT / VOL_TO_INT for integers
 * that differ per lane. The lanes kernel makes the functions overloadable, so both instances
 * keep their names. */
#ifndef FOGCL_VOLUME_COMMON_H
#define FOGCL_VOLUME_COMMON_H

#ifdef __OPENCL_C_VERSION__
#ifndef VOL_FN /* the lanes kernel makes them overloadable */
#define VOL_FN static inline
#endif
#define VOL_REAL float
#define VOL_V3 float3
#define VOL_V4 float4
#define VOL_MAKE3(x, y, z) ((float3)((x), (y), (z)))
#define VOL_MAKE4(x, y, z, w) ((float4)((x), (y), (z), (w)))
#define VOL_GLOBAL global
#define VOL_T(f) f
#define VOL_UINT uint
#define VOL_BYTE uchar
#define VOL_U float
#define VOL_U3 float3
#define VOL_MAKEU3(x, y, z) ((float3)((x), (y), (z)))
#define VOL_INT int
#define VOL_TO_INT(x) ((int)(x))
#else
#define VOL_FN template <typename VOL_REAL> inline
#define VOL_V3 glm::vec<3, VOL_REAL>
#define VOL_V4 glm::vec<4, VOL_REAL>
#define VOL_MAKE3(x, y, z) VOL_V3((x), (y), (z))
#define VOL_MAKE4(x, y, z, w) VOL_V4((x), (y), (z), (w))
#define VOL_GLOBAL
#define VOL_T(f) f<VOL_REAL>
#define VOL_UINT std::uint32_t
#define VOL_BYTE std::uint8_t
#define VOL_U VOL_REAL
#define VOL_U3 VOL_V3
#define VOL_MAKEU3(x, y, z) VOL_V3((x), (y), (z))
#define VOL_INT int
#define VOL_TO_INT(x) int(x)
#endif
#define VOL_ANY(m) (m) /* the lanes instance: VOL_ANY16(m) */
#ifdef __OPENCL_C_VERSION__
/* any(m) of a 16-lane mask (lanes -1 / 0) as one or-reduction: PoCL lowers OpenCL's any() on 16
 * lanes to a test and a branch per lane. */
#ifdef __clang__
#define VOL_ANY16(m) (__builtin_reduce_or(m) < 0)
#else
#define VOL_ANY16(m) any(m)
#endif
#endif

/* A packed parameter, read in the path's precision. */
#define VOL_P(array, index) ((VOL_REAL)(array)[index])
#define VOL_P3(array, index) VOL_MAKE3(VOL_P(array, index), VOL_P(array, (index) + 1), VOL_P(array, (index) + 2))
/* ... as a uniform: the same value in every lane. */
#define VOL_PU(array, index) ((VOL_U)(array)[index])
#define VOL_PU3(array, index) VOL_MAKEU3(VOL_PU(array, index), VOL_PU(array, (index) + 1), VOL_PU(array, (index) + 2))
#define VOL_P4(array, index) \
  VOL_MAKE4(VOL_P(array, index), VOL_P(array, (index) + 1), VOL_P(array, (index) + 2), VOL_P(array, (index) + 3))

/* Integrators (VOL_INTEGRATOR, VolumeIntegrator). */
#define VOL_STYLIZED 1
#define VOL_PHYSICAL 2
#define VOL_RIEMANN 3 /* the physical model with the textbook left Riemann sum (comparison only) */

/* The per-frame array (src/volume/volume_params.cpp packs it): camera, light, shadow map. */
#define VOL_F_EYE 0          /* world position of the camera (3) */
#define VOL_F_RIGHT 3        /* view -> world rotation columns (3 each) */
#define VOL_F_UP 6
#define VOL_F_FORWARD 9
#define VOL_F_CORNERS 12     /* view-space far corner rays, Corner order bl br tl tr (4 x 3) */
#define VOL_F_NEAR 24
#define VOL_F_FAR 25
#define VOL_F_ZX 26          /* _ZBufferParams.x, .y */
#define VOL_F_ZY 27
#define VOL_F_CORNER_Z 28    /* view z of the corner rays: far, or 1 with an infinite far plane */
#define VOL_F_LIGHT_DIR 29   /* unit, toward the light (3) */
#define VOL_F_LIGHT_COLOR 32 /* (3) */
#define VOL_F_TIME 35
#define VOL_F_WIDTH 36       /* the full-resolution frame */
#define VOL_F_HEIGHT 37
#define VOL_F_SCALE 38       /* resolution divisor s: 1, 2 or 4 */
#define VOL_F_LOW_WIDTH 39   /* ceil(W / s), ceil(H / s) */
#define VOL_F_LOW_HEIGHT 40
#define VOL_F_SHADOW_MATRIX 41 /* world -> light clip, column-major (16) */
#define VOL_F_SHADOW_WIDTH 57
#define VOL_F_SHADOW_HEIGHT 58
#define VOL_F_SHADOW_BIAS 59
#define VOL_F_INV_NEAR 60    /* 1 / near, 1 / far (0 with an infinite far plane), rounded once */
#define VOL_F_INV_FAR 61
#define VOL_F_LIGHT_COUNT 62 /* local lights (VOL_FEATURE_LIGHTS), at most VOL_MAX_LIGHTS */
#define VOL_F_LIGHT_OFFSET 63 /* where their VOL_L_* entries start in the volumes' array [floats] */
/* The marched height fog (VOL_FEATURE_HEIGHT, docs/DESIGN.md §6.5): */
#define VOL_F_HEIGHT_P 64    /* fog_math.h's FOG_HP_* constants (FOG_HP_COUNT = 19) */
#define VOL_F_HEIGHT_BASE 83 /* base height b [world y] */
#define VOL_F_HEIGHT_SUN 84  /* unit, toward the sun of the lobe (3) */
#define VOL_F_HEIGHT_REACH 87 /* an infinite ray's marched stretch ends at this eye depth (0: none) */
#define VOL_F_COUNT 88

/* One volume's parameters (docs/volumetric.md §A volume), resolved defaults included. */
#define VOL_V_CENTER 0       /* (3) */
#define VOL_V_RADIUS 3
#define VOL_V_DENSITY 4
#define VOL_V_MAX_Y 5
#define VOL_V_FADE_Y 6
#define VOL_V_FADE_EDGE 7
#define VOL_V_PROXIMITY_FADE 8
#define VOL_V_FOG_EXPONENT 9
#define VOL_V_FOG_CUTOFF 10
#define VOL_V_DETAIL_EXPONENT 11
#define VOL_V_DETAIL_STRENGTH 12
#define VOL_V_FOG_COLOR 13   /* (4) */
#define VOL_V_DIR_FOG_COLOR 17 /* (4) */
#define VOL_V_DIR_FALLOFF 21
#define VOL_V_LIGHT_CONTRIBUTION 22
#define VOL_V_DIR_LIGHT_CONTRIBUTION 23
#define VOL_V_SHADOW_STRENGTH 24
#define VOL_V_SHADOW_REVERSE_STRENGTH 25
#define VOL_V_TILING 26      /* (3) */
#define VOL_V_SPEED 29       /* (3) */
#define VOL_V_DETAIL_TILING 32 /* (3) */
#define VOL_V_DETAIL_SPEED_MODIFIER 35
#define VOL_V_OVERSHOOT 36
#define VOL_V_NOISE 37       /* 1: noise shapes the density, 0: density field 1 */
#define VOL_V_ALBEDO 38      /* (3) */
#define VOL_V_ANISOTROPY 41
#define VOL_V_AMBIENT 42     /* (3) */
#define VOL_V_STRIDE 48

/* One local light (docs/volumetric.md#local-lights), after the volumes in their array. */
#define VOL_L_POSITION 0     /* [world] (3) */
#define VOL_L_RADIANCE 3     /* intensity * color (3) */
#define VOL_L_RANGE 6        /* [world] */
#define VOL_L_INV_RANGE2 7   /* 1 / range^2: the window (1 - d^2 / range^2)^2 */
#define VOL_L_RADIUS2 8      /* source radius^2 [world^2]: 1 / (d^2 + radius^2) */
#define VOL_L_AXIS 9         /* spot: unit axis, from the light outward (3) */
#define VOL_L_SPOT_SCALE 12  /* spot: cone = saturate(cos * scale + offset)^2; point: scale 0, offset 1 */
#define VOL_L_SPOT_OFFSET 13
#define VOL_L_STRIDE 16

/* The seed's constants, named where the march uses them. */
#define VOL_JITTER_SPAN 0.1f       /* stylized start offset: -jitter * step * 0.1 */
#define VOL_ADAPTIVE_ONSET 0.1f    /* stylized: refine once the noise exceeds this */
#define VOL_ADAPTIVE_FACTOR 0.2f   /* ... to steps of 0.2 * step */
#define VOL_ADAPTIVE_BACK 4.0f     /* ... after going back 4 small steps */
#define VOL_LIGHT_FLOOR 0.1f       /* stylized: color never below 0.1 * light color */

#endif
