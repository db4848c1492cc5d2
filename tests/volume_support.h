// Shared scenes of the volumetric tests: the demo frame with fog volumes around its spheres, and
// error measures against the scalar<double> reference.
#pragma once

#include <string>

#include "fogcl/demo_scene.h"
#include "fogcl/volume_pass.h"
#include "fogcl/volume_scalar.h"
#include "test_support.h"

namespace fogcl::test {

struct VolumeTestScene {
  DemoFrame frame;
  VolumeScene scene;
};

// The demo scene at width x height with three volumes: one around the camera, one behind the
// (2.2, 1, -0.5) sphere, one crossing the ground; the light of the demo scene.
VolumeTestScene volume_test_scene(int width, int height, ColorFormat format = ColorFormat::rgba32f,
                                  bool reversed_z = false);

// A top-down shadow map (light looking along -y, orthographic over x, z in [-15, 15] + (0, 4)):
// a disc blocker of radius 3 at height 2 above (0, 0); the ground (height 0) elsewhere.
ShadowMap synthetic_shadow_map(bool reversed_z);

// The pose of a DemoView (forward = target - eye, up = +y).
CameraPose pose_of(const DemoView& view);

struct VolumeErrorStats {
  double max_abs = 0;          // max |got - ref| over RGB
  double p999 = 0;             // 99.9th percentile of the per-pixel max |got - ref|
  std::size_t over = 0;        // pixels whose max |got - ref| exceeds `tolerance`
  std::size_t nonfinite = 0;   // non-finite outputs
  std::size_t pixels = 0;
  std::size_t fogged = 0;      // pixels the reference covers (A > 0)
};
VolumeErrorStats compare_volumes(const ColorImage& got, const VolumeResult<double>& ref, double tolerance);
std::string describe(const VolumeErrorStats& s);

}  // namespace fogcl::test
