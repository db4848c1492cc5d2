// The per-pixel formulas of kernels/fog_math.h as C++ function templates, in namespace
// fogcl::formulas. The one way host code reaches them (the scalar path, depth conversions).
#pragma once

#include <cmath>

namespace fogcl::formulas {
using std::exp2;
using std::expm1;
using std::fma;
using std::fmax;
using std::fmin;
using std::isnan;
using std::sqrt;
#define FOG_INT int
#define FOG_NAME(name) name
#include "fog_math.h"
#undef FOG_INT
#undef FOG_NAME
}  // namespace fogcl::formulas
