// The volumetric pass's shared kernel headers (kernels/volume_*.h) as C++ function templates in
// fogcl::volume_formulas: the one way host code reaches the march, the upsampling and the
// composite (the scalar path in float and double). The kernels compile the same text.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>
#include <glm/common.hpp>

#include "pass/formulas.h"

namespace fogcl::volume_formulas {
using namespace fogcl::formulas;
using glm::dot;
using glm::floor;
using glm::length;
using glm::normalize;
using std::atan;
using std::atan2;
using std::ceil;
using std::exp;
using std::expm1;
using std::floor;
using std::max;
using std::min;
using std::pow;
using std::size_t;
using std::tan;

#include "volume_common.h"
#include "volume_ray.h"
#include "volume_noise.h"
#include "volume_integrate.h"
#include "volume_composite.h"
}  // namespace fogcl::volume_formulas
