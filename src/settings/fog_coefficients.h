// Per-frame constants of the fog factor (UnityCG.cginc's unity_FogParams), computed in the
// precision T of the path that uses them: float for the kernel and the scalar baseline, double
// for the reference. The per-pixel formulas that consume them are in kernels/fog_math.h.
#pragma once

#include <cmath>
#include <limits>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "camera/camera_basis.h"
#include "fogcl/camera.h"
#include "fogcl/fog_settings.h"
#include "fogcl/variant.h"
#include "pass/formulas.h"

namespace fogcl::detail {

template <class T>
struct FogCoefficients {
  T a = 0;  // linear: end; step: start; exp: density * log2(e); exp2: density / sqrt(ln 2)
  T b = 0;  // linear: 1 / (end - start); exp, exp2: density (for the fog amount); step: unused
};

template <class T>
FogCoefficients<T> fog_coefficients(const FogSettings& s, KernelMode mode) {
  constexpr double kLog2e = 1.44269504088896340736;        // 1 / ln 2
  constexpr double kInvSqrtLn2 = 1.20112240878644803896;   // 1 / sqrt(ln 2)
  // Held to the largest finite T: a density near FLT_MAX (or end - start under FLT_MIN) would
  // make the factor +inf, and distance 0 times it NaN; its largest finite value gives e^0 = 1.
  const auto finite = [](T x) { return std::fmin(x, std::numeric_limits<T>::max()); };
  FogCoefficients<T> c;
  switch (mode) {
    case KernelMode::linear:
      c.a = T(s.end);
      c.b = finite(T(1) / (T(s.end) - T(s.start)));
      break;
    case KernelMode::linear_step:
      c.a = T(s.start);
      break;
    case KernelMode::exp:
      c.a = finite(T(s.density) * T(kLog2e));
      c.b = T(s.density);
      break;
    case KernelMode::exp2:
      c.a = finite(T(s.density) * T(kInvSqrtLn2));
      c.b = T(s.density);
      break;
    case KernelMode::none:
    case KernelMode::height:
      break;
  }
  return c;
}

// Height fog's coefficients per channel (docs/DESIGN.md §6.1): the extinction beta_ext (unset: the
// density in every channel) and the in-scattering beta_in (unset: the extinction).
inline glm::vec3 height_extinction(const FogSettings& s) { return s.height.extinction.value_or(glm::vec3(s.density)); }
inline glm::vec3 height_inscattering(const FogSettings& s) {
  return s.height.inscattering.value_or(height_extinction(s));
}

// The per-frame constants of height fog (docs/DESIGN.md §6) in T: the FOG_HP_* block of
// kernels/fog_math.h, and the camera in view space, so that a pixel needs no rotation: ω.y =
// dot(ω_view, up) and cos(ω, ℓ) from ω_view and light. The rotation is computed in double and
// rounded once to T.
template <class T>
struct HeightCoefficients {
  T p[FOG_HP_COUNT] = {};
  T d0 = 0;         // eye.y - base height
  T up[3] = {};     // world +y in view space (R^T (0, 1, 0)); orthographic: also ω.y = up[2]
  T light[3] = {};  // the unit direction toward the light in view space (R^T ℓ)
};

template <class T>
HeightCoefficients<T> height_coefficients(const FogSettings& s, const CameraParams& cam) {
  HeightCoefficients<T> c;
  const HeightFogSettings& h = s.height;
  const glm::vec3 ext = height_extinction(s), in = height_inscattering(s);
  c.p[FOG_HP_K] = T(h.falloff);
  c.p[FOG_HP_START] = T(h.start);
  c.p[FOG_HP_CUTOFF] = T(h.cutoff);
  c.p[FOG_HP_MAX] = T(h.max_opacity);
  c.p[FOG_HP_MIN_T] = T(1) - T(h.max_opacity);
  for (int k = 0; k < 3; ++k) {
    c.p[FOG_HP_EXT + k] = T(ext[k]);
    c.p[FOG_HP_IN + k] = T(in[k]);
    c.p[FOG_HP_FOG + k] = T(s.color[k]);
  }
  const CameraPose pose = cam.pose.value_or(CameraPose{});
  const CameraBasis b = camera_basis(pose);
  const glm::dvec3 &r = b.right, &u = b.up, &f = b.forward;
  c.d0 = T(double(pose.eye.y) - double(h.base_height));
  c.up[0] = T(r.y);
  c.up[1] = T(u.y);
  c.up[2] = T(f.y);
  if (h.sun) {
    c.p[FOG_HP_SUN_EXP] = T(h.sun->exponent);
    c.p[FOG_HP_SUN_START] = T(h.sun->start);
    for (int k = 0; k < 3; ++k) c.p[FOG_HP_SUN + k] = T(h.sun->color[k]);
    const glm::dvec3 l = glm::normalize(glm::dvec3(h.sun->direction));
    c.light[0] = T(glm::dot(r, l));
    c.light[1] = T(glm::dot(u, l));
    c.light[2] = T(glm::dot(f, l));
  }
  return c;
}

}  // namespace fogcl::detail
