// The volumetric pass on the OpenCL device against the scalar<double> reference, for every
// variant (integrator x noise x shadow map x resolution x storage): explicit budgets, the worst
// error printed.
#include <algorithm>
#include <cmath>
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

// Shadow maps (both Z conventions), reversed-Z frames and the noise as an image: on the
// stylized and the physical integrator at half resolution.
class VolumeKernelFeatures : public ::testing::TestWithParam<std::tuple<VolumeIntegrator, int>> {};

TEST_P(VolumeKernelFeatures, WithinBudget) {
  FOGCL_REQUIRE_DEVICE();
  const auto [integrator, feature] = GetParam();
  const char* names[] = {"shadow map", "shadow map, reversed Z", "reversed-Z frame", "noise image"};
  VolumeTestScene t = volume_test_scene(96, 54, ColorFormat::rgba32f, feature == 2);
  VolumeSettings settings;
  settings.integrator = integrator;
  settings.steps = 32;
  ShadowMap shadow;
  const bool with_shadow = feature <= 1;
  if (with_shadow) shadow = synthetic_shadow_map(feature == 1);
  if (feature == 3) {
    if (wrap(runtime()->device()).getInfo<CL_DEVICE_IMAGE_SUPPORT>() != CL_TRUE) GTEST_SKIP() << "no image support";
    settings.noise_sampling = NoiseSampling::image;
  }
  ColorImage out;
  volume_pass().apply(t.frame.color, t.frame.depth, out, t.frame.params, t.scene, settings,
                      with_shadow ? &shadow : nullptr);
  const VolumeResult<double> ref = volumes_scalar<double>(t.frame.color, t.frame.depth, t.frame.params, t.scene,
                                                          settings, with_shadow ? &shadow : nullptr);
  // The image sampler filters in its own arithmetic (on GPUs with 8-bit weights): looser budget.
  const double tolerance = feature == 3 ? 2e-2 : 2e-4;
  const VolumeErrorStats s = compare_volumes(out, ref, tolerance);
  std::printf("  %s, %s: %s (options: %s)\n", to_string(integrator), names[feature], describe(s).c_str(),
              volume_pass().last_march_options().c_str());
  EXPECT_EQ(s.nonfinite, 0u);
  EXPECT_LE(s.over, s.pixels / 1000) << describe(s);
  if (with_shadow) {
    // The shadow really darkens something: the same frame without it differs.
    const VolumeResult<double> lit = volumes_scalar<double>(t.frame.color, t.frame.depth, t.frame.params, t.scene, settings);
    double change = 0;
    for (std::size_t i = 0; i < lit.rgba.size(); ++i) change = std::max(change, std::fabs(lit.rgba[i] - ref.rgba[i]));
    std::printf("    largest change the shadow map makes: %.3g\n", change);
    EXPECT_GT(change, 1e-2);
  }
}

INSTANTIATE_TEST_SUITE_P(Features, VolumeKernelFeatures,
                         ::testing::Combine(::testing::Values(VolumeIntegrator::stylized, VolumeIntegrator::physical),
                                            ::testing::Range(0, 4)));

INSTANTIATE_TEST_SUITE_P(Variants, VolumeKernelVsReference,
                         ::testing::Combine(::testing::Values(VolumeIntegrator::stylized, VolumeIntegrator::physical),
                                            ::testing::Bool(), ::testing::Values(1, 2, 4),
                                            ::testing::Values(ColorFormat::rgba32f, ColorFormat::rgba16f)));

}  // namespace
}  // namespace fogcl::test
