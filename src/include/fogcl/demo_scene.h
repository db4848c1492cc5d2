// The built-in test scene of Catlike Coding's "Rendering 14: Fog": a few gray-white spheres on a
// ground plane under a sky, ray cast analytically so color and depth are exact for the camera.
//
// World (Unity's: left-handed, +x right, +y up, +z forward), in world units:
// - ground: the plane y = 0, infinite, albedo 0.80 with a faint 2-unit checker (0.80 / 0.72) that
//   fades to its mean where a square would cover less than two 1-mrad pixels (a
//   function of the ray only: the color of a ray does not depend on the resolution);
// - 7 spheres, albedo ~0.8, centre (radius): (-0.9, 0.5, -3.5) (0.5), (2.2, 1, -0.5) (1),
//   (-3.8, 1.5, 7) (1.5), (-12, 2, 16) (2), (-3, 3, 27) (3), (5, 4, 42) (4), (34, 5, 56) (5):
//   each rests on the ground, about 2.9 to 71 units from the default eye;
// - light: one directional light from normalize(0.35, 0.8, -0.5) (behind the default camera,
//   to its right and above), color (1, 0.96, 0.9), Lambert, hard shadows cast by the spheres;
//   ambient (0.22, 0.25, 0.3);
// - sky: a vertical gradient from (0.85, 0.93, 1.1) at the horizon to (0.3, 0.5, 0.9) at the
//   zenith; it is also what pixels show where the ground lies beyond the far plane.
// One ray per pixel centre, in double, no anti-aliasing: pixel (x, y) takes the ray of docs/DESIGN.md
// §2 (u = (x + 0.5) / W, v = 1 - (y + 0.5) / H, bilinear in the frustum corners) rotated into the
// world by the DemoView basis; its depth is the raw device depth of the hit for the camera
// (Linear01Depth(raw) = z_eye / far with the float _ZBufferParams), sky depth 1 (conventional Z)
// or 0 (reversed Z).
#pragma once

#include <optional>
#include <vector>

#include <glm/vec3.hpp>

#include "fogcl/camera.h"
#include "fogcl/fog_settings.h"
#include "fogcl/image.h"
#include "fogcl/volumes.h"

namespace fogcl {

struct DemoFrame {
  ColorImage color;   // linear RGB, alpha 1 everywhere
  DepthImage depth;   // raw device depth for the camera (sky: 1 conventional, 0 reversed Z)
  PerspectiveCamera camera;
  CameraParams params;  // make_camera_params(camera)
};

// Camera placement in the world: eye at `eye`, looking at `target`, +y up (view +x is image right;
// looking along +z, image right is world +x). Throws fogcl::Error if target == eye, the eye is inside a sphere or the view
// direction is parallel to +y.
struct DemoView {
  glm::vec3 eye{0.0f, 1.6f, -6.0f};    // [world units]
  glm::vec3 target{0.0f, 0.6f, 10.0f};
};

// Renders width x height pixels (>= 1 each, else fogcl::Error). camera.aspect is ignored and set to
// float(width) / float(height); the camera is validated as make_camera_params does. to_light: the
// direction toward the sun that shades and shadows the scene (any length; finite, non-zero, not
// vertical, else fogcl::Error); unset: demo_light()'s.
DemoFrame render_demo_scene(int width, int height, PerspectiveCamera camera = {},
                            const DemoView& view = {}, ColorFormat format = ColorFormat::rgba32f,
                            const std::optional<glm::vec3>& to_light = std::nullopt);

// The scene's directional light as the volumetric pass takes it: direction normalize(0.35, 0.8,
// -0.5) (toward the light, behind the default camera), color (1, 0.96, 0.9); with to_light, that
// direction normalised (the rules of render_demo_scene's).
MainLight demo_light(const std::optional<glm::vec3>& to_light = std::nullopt);

// A low sun ahead of the default view (about 12 degrees up, a little left of the view direction;
// demo_light's color): the light-shaft scenes' sun, which the spheres shadow toward the camera
// (fogcl demo's height-shafts rows, the volume report's "shafts" scene).
MainLight demo_low_sun();

// The world region demo_shadow_map() covers: every sphere, the ground and the air up to y = 12
// around the default view (x in [-25, 45], z in [-15, 65]).
struct DemoShadowRegion {
  glm::vec3 min{-25.0f, 0.0f, -15.0f};
  glm::vec3 max{45.0f, 12.0f, 65.0f};
};

// The scene's depth as its directional light sees it: an orthographic light camera looking along
// -demo_light().direction, fitted to `region` (its 8 corners lie inside the view volume, with 1
// world unit to spare on every side), the same spheres and ground ray cast in double, one ray per texel
// centre. Depth is float32 conventional Z in [0, 1] (0 at the light's near plane, linear in
// distance along the light); a texel whose ray meets nothing before the far plane holds 1. The
// params' world_to_light_clip follows ShadowMapParams: clip xy in [-1, 1] -> the map's uv (v = 0
// at the bottom row), clip z / w (w = 1) the stored depth. width, height >= 1. to_light: as
// render_demo_scene's (unset: demo_light()'s direction).
ShadowMap render_demo_shadow_map(int width = 1024, int height = 1024, const DemoShadowRegion& region = {},
                                 const std::optional<glm::vec3>& to_light = std::nullopt);

// The demo's four fog volumes, in this order: one around the default eye (the camera is inside),
// one behind the (2.2, 1, -0.5) sphere, one crossing the ground, a wide bank around the far
// spheres. Noise tiling 0.1-0.25 per world unit (a few billows per volume in this ~50-unit scene),
// fades of a few units. For the physical integrator the densities become sigma_t = 0.15 x the
// stylized alpha scale, with a sky-coloured ambient and mild forward scattering (g = 0.2).
std::vector<FogVolume> demo_fog_volumes(VolumeIntegrator integrator);

// The light-shaft scenes' fog (fogcl demo's height-shafts rows, the volume report's "shafts"):
// a height fog lying on the ground (FogMode::height, beta = 0.09 at y = 0, falloff 0.3, fogged
// sky) with a sun lobe toward demo_low_sun(), marched with VolumeSettings::height_fog so the
// render_demo_shadow_map(..., demo_low_sun().direction) map cuts shafts into it.
FogSettings demo_shaft_fog();

// Street lamps for the night scenes (fogcl demo's street-lamps rows, the volume report's "lamps"):
// four spot lights on 4.5-unit poles pointing down (warm, intensity 50, range 14, cones 20-38
// degrees), three along the left of the default view and one on the right, and two point-light
// lanterns near the ground (cool blue and orange).
std::vector<LocalLight> demo_street_lamps();

// The night scenes' fog: a ground mist (FogMode::height, beta = 0.12 at y = 0, falloff 0.25,
// fogged sky, cut off at 60 units) lit by a dim blue ambient and no sun lobe, marched with
// VolumeSettings::height_fog so the lamps glow in it. The night frame is demo_night_frame()'s.
FogSettings demo_night_fog();

// The demo frame at night: render_demo_scene's colors times 0.04 (depth unchanged), so the fog's
// lamps are what lights the view.
DemoFrame demo_night_frame(int width, int height);

}  // namespace fogcl
