// What the scene asks of the fog (Unity's RenderSettings fog + Catlike Coding's deferred fog).
#pragma once

#include <glm/vec3.hpp>

namespace fogcl {

enum class FogMode {
  off,     // no pass runs; output = input, bit for bit
  linear,  // f = (end - d) / (end - start); start == end is a hard step at start
  exp,     // f = e^(-density d)
  exp2,    // f = e^(-(density d)^2)
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
};

// Throws fogcl::Error naming the value and the rule (NaN or negative density, start > end, ...).
// Parameters the mode does not use are not checked.
void validate(const FogSettings& settings);

const char* to_string(FogMode mode);
const char* to_string(FogMetric metric);
const char* to_string(Precision precision);
const char* to_string(SkyDistance sky);

}  // namespace fogcl
