// A reference for the local lights of the volume march (docs/volumetric.md#local-lights) written
// from the documented definitions alone, in long double: the in-scattered radiance of point and
// spot lights along one ray through spheres of constant extinction, by Gauss-Legendre quadrature.
// It includes none of the library's formula headers (volume_formulas.h and the kernels' headers),
// so a wrong constant or formula there shows as a difference here.
#pragma once

#include <vector>

#include <glm/vec3.hpp>

#include "fogcl/volumes.h"

namespace fogcl::test::light_reference {

// A sphere of constant extinction sigma_t [1/world] with its single-scattering albedo and
// Henyey-Greenstein g; overlapping spheres add.
struct Medium {
  glm::dvec3 center{0.0};
  double radius = 1.0;
  double sigma_t = 0.0;
  glm::dvec3 albedo{1.0};
  double g = 0.0;
};

// The lights' in-scattered radiance along origin + t dir (dir unit), t in [0, t_end] (t_end
// finite): ∫ T(t) Σ_media albedo σ_t HG(cos θ) I color W(d) cone / (d² + radius²) dt, T(t) the
// media's transmittance from the origin. The integral is cut at every sphere boundary, every
// light's range sphere and its closest approach, and each piece takes `panels` panels of 8-point
// Gauss-Legendre quadrature, graded geometrically toward the piece's ends (where a light's peak is).
glm::dvec3 inscattered(const glm::dvec3& origin, const glm::dvec3& dir, double t_end, const std::vector<Medium>& media,
                       const std::vector<LocalLight>& lights, long panels);

// T(t_end): e^-(Σ σ_t x the chord's length in each sphere).
double transmittance(const glm::dvec3& origin, const glm::dvec3& dir, double t_end, const std::vector<Medium>& media);

}  // namespace fogcl::test::light_reference
