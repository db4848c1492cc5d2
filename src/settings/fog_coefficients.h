// Per-frame constants of the fog factor (UnityCG.cginc's unity_FogParams), computed in the
// precision T of the path that uses them: float for the kernel and the scalar baseline, double
// for the reference. The per-pixel formulas that consume them are in kernels/fog_math.h.
#pragma once

#include "fogcl/fog_settings.h"
#include "fogcl/variant.h"

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
  FogCoefficients<T> c;
  switch (mode) {
    case KernelMode::linear:
      c.a = T(s.end);
      c.b = T(1) / (T(s.end) - T(s.start));
      break;
    case KernelMode::linear_step:
      c.a = T(s.start);
      break;
    case KernelMode::exp:
      c.a = T(s.density) * T(kLog2e);
      c.b = T(s.density);
      break;
    case KernelMode::exp2:
      c.a = T(s.density) * T(kInvSqrtLn2);
      c.b = T(s.density);
      break;
    case KernelMode::none:
      break;
  }
  return c;
}

}  // namespace fogcl::detail
