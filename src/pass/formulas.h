// The per-pixel formulas of kernels/fog_math.h as C++ function templates, in namespace
// fogcl::formulas. The one way host code reaches them (the scalar path, depth conversions).
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>

#include <glm/vec3.hpp>

#include "fogcl/camera.h"

namespace fogcl::formulas {
using std::exp;
using std::expm1;
using std::fabs;
using std::floor;
using std::fma;
using std::log1p;
using std::fmax;
using std::fmin;
using std::isinf;
using std::isnan;
using std::sqrt;

inline int fog_trunc_int(float x) { return int(x); }
inline float fog_to_real(int n) { return float(n); }
inline float fog_as_real(std::int32_t i) {
  float x;
  std::memcpy(&x, &i, sizeof x);
  return x;
}
// The exp2 of the fog factors, 2^min(x, 0): float paths run the kernel's polynomial (the same
// bits as the OpenCL kernel), the double reference the C library's exp2. Declared before the templates
// that call it: lookup of a dependent call on a fundamental type happens at their definition.
inline float fog_exp2(float x);
inline double fog_exp2(double x) { return std::exp2(std::fmin(x, 0.0)); }
inline std::int32_t fog_as_int(float x) {
  std::int32_t i;
  std::memcpy(&i, &x, sizeof i);
  return i;
}
// Height fog's exp, expm1 and log1p: the float paths the kernel's polynomials (fog_exp_poly, ...),
// the double reference the C library's.
inline float fog_exp(float x);
inline float fog_expm1(float x);
inline float fog_log1p(float x);
inline double fog_exp(double x) { return std::exp(x); }
inline double fog_expm1(double x) { return std::expm1(x); }
inline double fog_log1p(double x) { return std::log1p(x); }
inline float fog_exp_expm1(float x, float* expm1_x);
inline double fog_exp_expm1(double x, double* expm1_x) {
  *expm1_x = std::expm1(x);
  return std::exp(x);
}

#define FOG_INT int
#define FOG_NAME(name) name
#define FOG_TRUNC_INT fog_trunc_int
#define FOG_TO_REAL fog_to_real
#define FOG_AS_REAL fog_as_real
#define FOG_EXP2 fog_exp2
#define FOG_EXP fog_exp
#define FOG_EXP_NEG fog_exp
#define FOG_EXPM1 fog_expm1
#define FOG_LOG1P fog_log1p
#define FOG_EXP_EXPM1 fog_exp_expm1
#define FOG_AS_INT fog_as_int
#define FOG_CLAMP_BY_SELECT
#include "fog_math.h"  // undefines the instance macros
#undef FOG_EXP2
#undef FOG_EXP
#undef FOG_EXP_NEG
#undef FOG_EXPM1
#undef FOG_LOG1P
#undef FOG_EXP_EXPM1
#undef FOG_CLAMP_BY_SELECT

inline float fog_exp2(float x) { return fog_exp2_poly(x); }
inline float fog_exp(float x) { return fog_exp_poly(x); }
inline float fog_expm1(float x) { return fog_expm1_neg_poly(x); }
inline float fog_log1p(float x) { return fog_log1p_neg_poly(x); }
inline float fog_exp_expm1(float x, float* expm1_x) { return fog_exp_expm1_neg_poly(x, expm1_x); }

// The ray of a pixel: each component interpolated from the frustum corners (fog_bilerp). The
// kernel composes the same formulas on its vector types. Always inlined: it sits in per-pixel
// loops that are vectorised or compiled for FMA (scalar_fog.cpp).
template <class T>
[[gnu::always_inline]] inline void fog_corner_ray(const std::array<glm::vec3, 4>& corners, T u, T v, T (&ray)[3]) {
  for (int k = 0; k < 3; ++k)
    ray[k] = fog_bilerp(T(corners[kBottomLeft][k]), T(corners[kBottomRight][k]), T(corners[kTopLeft][k]),
                        T(corners[kTopRight][k]), u, v);
}

// The ray term of a pixel (fog_ray_term: |ray(u, v)|, or its square where `squared`).
template <class T>
[[gnu::always_inline]] inline T fog_corner_ray_term(const std::array<glm::vec3, 4>& corners, T u, T v,
                                                    int squared) {
  T ray[3];
  fog_corner_ray(corners, u, v, ray);
  return fog_ray_term(ray[0], ray[1], ray[2], squared);
}

// The corner rays the formulas interpolate (kernel arguments and the scalar path alike): at the
// far plane for raw depth (Linear01Depth scales them); at view z = 1 for linear depth, which
// scales them by eye depth (fog_view_distance_linear). Infinite-far corners are at z = 1 already.
inline std::array<glm::vec3, 4> fog_ray_corners(const CameraParams& camera) {
  std::array<glm::vec3, 4> corners = camera.frustum_corners;
  if (camera.depth_kind != DepthKind::raw && camera.projection == Projection::perspective)
    for (glm::vec3& c : corners) c = glm::vec3(c.x / c.z, c.y / c.z, 1.0f);
  return corners;
}
}  // namespace fogcl::formulas
