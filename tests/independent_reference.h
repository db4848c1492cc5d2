// A reference for the deferred pass written from docs/DESIGN.md's definitions alone (§2's Unity
// factors, §6's height-fog integral by quadrature), in double and long double. It includes none of
// the library's formula headers (formulas.h, fog_math.h, fog_coefficients.h, volume_formulas.h):
// a wrong constant or a wrong formula there shows as a difference here, where a float64 instance
// of the same formulas would agree with it.
#pragma once

#include <functional>
#include <vector>

#include "fogcl/camera.h"
#include "fogcl/fog_settings.h"
#include "fogcl/image.h"
#include "fogcl/volumes.h"

namespace fogcl::test::independent {

// The output of one frame: rgb per pixel (alpha passes through and is not stored) and, for the
// deferred modes, the fog factor f (height fog: the red channel's transmittance T).
struct Reference {
  int width = 0, height = 0;
  std::vector<double> rgb;     // 3 * width * height
  std::vector<double> factor;  // width * height
};

// docs/DESIGN.md §2: linear, step, exp and exp2 fog on raw depth (perspective, reversed Z, the
// infinite far plane), depth- or distance-based, with the sky test, the fogged skybox and the sky
// at infinity, and the blend. Unity's factors as they are defined: (end - d) / (end - start)
// clamped, e^(-ρd), e^(-(ρd)^2).
Reference deferred_fog(const ColorImage& color, const DepthImage& depth, const CameraParams& camera,
                       const FogSettings& settings);

// docs/DESIGN.md §6: height fog on raw depth (perspective and the infinite far plane), with H and
// H_sun integrated numerically along each pixel's ray (height_integral), never §6.2's closed form.
// settings.mode must be FogMode::height and camera.pose set.
Reference height_fog(const ColorImage& color, const DepthImage& depth, const CameraParams& camera,
                     const FogSettings& settings);

// docs/volumetric.md's stylized integrator on spheres of constant density (noise off, no fades, no
// shadow map, no jitter) at full resolution, composited: the march then accumulates exactly what
// it marches (adaptive stepping: all but the first, skipped, sample), so each volume's alpha is
// fog_color.a·saturate(density·accumulated/marched) and its color the lobe's, and the volumes
// are drawn in order with the seed's blend and composited as P + color·(1 - A). `certain` is 0
// where the definition is discontinuous within 1e-4 of the pixel's ray (a grazing ray, an occluder
// at a sphere's front), where float rounding may take either side. Perspective raw depth.
struct VolumeReference {
  Reference frame;
  std::vector<char> certain;  // per pixel
};
VolumeReference stylized_volumes(const ColorImage& color, const DepthImage& depth, const CameraParams& camera,
                                 const VolumeScene& scene, const VolumeSettings& settings);

// ∫[a, b] g(s) ds by 8-point Gauss-Legendre quadrature on `panels` equal panels, in long double
// (nodes from Newton's iteration on P_8).
long double gauss_legendre(const std::function<long double(long double)>& g, long double a, long double b,
                           long long panels);

// H = ∫[s0, s1] e^(-k (y0 + s wy - b)) ds (s1 may be +inf: then the tail beyond the point where the
// integrand has fallen by e^-80 is left out; +inf where it does not fall). Panels are narrow enough
// that the integrand changes by at most e^2 over one.
long double height_integral(long double s0, long double s1, long double y0, long double wy, long double k,
                            long double b);

}  // namespace fogcl::test::independent
