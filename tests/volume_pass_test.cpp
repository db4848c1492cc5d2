// The volumetric pass on the OpenCL device against the scalar<double> reference, for every
// variant (integrator x noise x shadow map x resolution x storage): explicit budgets, the worst
// error printed.
#include <cstdio>
#include <tuple>

#include "volume_support.h"

namespace fogcl::test {
namespace {

VolumePass& volume_pass() {
  static VolumePass pass(*runtime());
  return pass;
}

struct VariantCase {
  VolumeIntegrator integrator;
  bool noise;
  int divisor;
  ColorFormat storage;
};

class VolumeKernelVsReference : public ::testing::TestWithParam<std::tuple<VolumeIntegrator, bool, int, ColorFormat>> {};

TEST_P(VolumeKernelVsReference, WithinBudget) {
  FOGCL_REQUIRE_DEVICE();
  const auto [integrator, noise, divisor, storage] = GetParam();
  VolumeTestScene t = volume_test_scene(96, 54, storage);
  for (FogVolume& v : t.scene.volumes) v.noise = noise;
  VolumeSettings settings;
  settings.integrator = integrator;
  settings.resolution_divisor = divisor;
  settings.steps = 32;
  t.scene.frame_index = 7;
  ColorImage out;
  volume_pass().apply(t.frame.color, t.frame.depth, out, t.frame.params, t.scene, settings);
  const VolumeResult<double> ref =
      volumes_scalar<double>(t.frame.color, t.frame.depth, t.frame.params, t.scene, settings);
  const double tolerance = storage == ColorFormat::rgba16f ? 4e-3 : 2e-4;
  const VolumeErrorStats s = compare_volumes(out, ref, tolerance);
  std::printf("  %s noise %d 1/%d %s: %s\n", to_string(integrator), int(noise), divisor, to_string(storage),
              describe(s).c_str());
  EXPECT_GT(s.fogged, s.pixels / 10);
  EXPECT_EQ(s.nonfinite, 0u);
  EXPECT_LE(s.over, s.pixels / 1000) << describe(s);
}

INSTANTIATE_TEST_SUITE_P(Variants, VolumeKernelVsReference,
                         ::testing::Combine(::testing::Values(VolumeIntegrator::stylized, VolumeIntegrator::physical),
                                            ::testing::Bool(), ::testing::Values(1, 2, 4),
                                            ::testing::Values(ColorFormat::rgba32f, ColorFormat::rgba16f)));

}  // namespace
}  // namespace fogcl::test
