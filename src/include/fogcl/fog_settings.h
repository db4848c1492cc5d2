// What the scene asks of the fog (Unity's RenderSettings fog + Catlike Coding's deferred fog).
#pragma once

#include <cmath>
#include <optional>

#include <glm/vec3.hpp>

namespace fogcl {

enum class FogMode {
  off,     // no pass runs; output = input, bit for bit
  linear,  // f = (end - d) / (end - start); start == end is a hard step at start
  exp,     // f = e^(-density d)
  exp2,    // f = e^(-(density d)^2)
  // Height and atmospheric fog (docs/DESIGN.md §6): along the ray from the eye, thinning with
  // height, per-channel extinction and in-scattering, an optional sun lobe (FogSettings::height).
  // Needs CameraParams::pose; the metric does not apply (always along the ray).
  height,
};

enum class FogMetric {
  depth,     // d = Linear01Depth * far - near (Unity's default, "depth-based")
  distance,  // d = |ray(u, v)| * Linear01Depth (radial distance from the eye)
};

// How far the sky (the background: raw depth at the far end, linear depth +inf or beyond far) is.
enum class SkyDistance {
  far_plane,  // at the far plane (Unity): fogged as d = far - near, and only with fog_skybox
  infinite,   // infinitely far (a renderer's mist pass): fully fogged in every mode; implies fog_skybox
};

// Precision of the kernel maths (docs/DESIGN.md §4). The scalar path ignores it.
enum class Precision {
  precise,  // OpenCL default maths (built-ins within their spec ulp bounds); the default
  fast,     // -cl-fast-relaxed-math and native_ built-ins
};

// The optional sun in-scattering lobe of height fog: rgb += S * max(cos θ, 0)^e * J_sun, θ the
// angle between the pixel's ray and the light, J_sun the fog amount from `start` on.
struct SunLobe {
  glm::vec3 direction{0.0f, 1.0f, 0.0f};  // toward the light, world space; finite, non-zero (normalised)
  glm::vec3 color{1.0f};                  // S, linear RGB; finite, >= 0 (all 0: no lobe)
  float exponent = 8.0f;                  // e, finite, > 0: larger is a tighter lobe
  float start = 0.0f;                     // s_sun [world units along the ray], finite, >= 0
};

// Height and atmospheric fog (FogMode::height; docs/DESIGN.md §6). Heights are world y (+y up,
// CameraParams::pose's world); distances are along each pixel's ray, from the eye. The fog color
// is FogSettings::color, the skybox FogSettings::fog_skybox (the sky is then an infinitely long
// ray, cut at `cutoff`), the precision FogSettings::precision.
struct HeightFogSettings {
  // beta_ext per channel [1/world unit]: finite, >= 0. Unset: FogSettings::density in all three.
  std::optional<glm::vec3> extinction;
  // beta_in per channel [1/world unit]: finite, >= 0. Unset: the extinction.
  std::optional<glm::vec3> inscattering;
  float falloff = 0.0f;      // k [1/world unit], finite: > 0 thins upward, < 0 thickens, 0 homogeneous
  float base_height = 0.0f;  // b [world y] where the coefficients hold; finite
  float start = 0.0f;        // s_start [world units along the ray]: no fog nearer; finite, >= 0
  float cutoff = INFINITY;   // s_cut [world units along the ray]: no fog farther; > start (+inf: none)
  float max_opacity = 1.0f;  // m in [0, 1]: T >= 1 - m, J <= m (0: no pass at all)
  std::optional<SunLobe> sun;  // no lobe (and no lobe code in the kernel) when unset
};

struct FogSettings {
  FogMode mode = FogMode::exp2;            // Unity default: ExponentialSquared
  glm::vec3 color{0.5f, 0.5f, 0.5f};       // linear RGB; finite, each |c| <= 65504 (half max)
  float start = 0.0f;                      // linear: fog begins [world units]; finite
  float end = 300.0f;                      // linear: fog is opaque [world units]; finite, >= start
  float density = 0.01f;                  // exp/exp2 [1/world unit]; finite, >= 0
  FogMetric metric = FogMetric::depth;
  bool fog_skybox = false;                 // false: sky pixels (Linear01Depth > 0.9999) stay unfogged
  SkyDistance sky = SkyDistance::far_plane;  // infinite: the sky is fully fogged (fog_skybox implied)
  Precision precision = Precision::precise;
  HeightFogSettings height;                // FogMode::height only
};

// Throws fogcl::Error naming the value and the rule (NaN or negative density, start > end, ...).
// Parameters the mode does not use are not checked.
void validate(const FogSettings& settings);

const char* to_string(FogMode mode);
const char* to_string(FogMetric metric);
const char* to_string(Precision precision);
const char* to_string(SkyDistance sky);

}  // namespace fogcl
