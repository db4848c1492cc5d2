// Kernel vs scalar<float> vs scalar<double> for every variant (mode x depth/distance x skybox x
// Z convention x f32/f16 storage) on 1x1, 7x5, 333x211 and 1920x1080. Budgets against the double
// path: 2e-6 absolute on the fog factor, 1e-5 relative on color (f32), 1 half ulp (f16) on top of
// the factor budget (see ErrorStats::max_half_ulps_beyond_factor).
#include <cstdio>
#include <map>
#include <optional>
#include <tuple>

#include "test_support.h"

namespace fogcl::test {
namespace {

constexpr double kFactorBudget = 2e-6;
constexpr double kColorRelBudget = 1e-5;
constexpr double kHalfUlpBudget = 1.0;
constexpr float kStepStart = 40.0f;

FogSettings settings_for(KernelMode mode, bool distance, bool skybox) {
  FogSettings s;
  s.color = glm::vec3(0.5f, 0.6f, 0.7f);
  s.metric = distance ? FogMetric::distance : FogMetric::depth;
  s.fog_skybox = skybox;
  switch (mode) {
    case KernelMode::linear: s.mode = FogMode::linear; s.start = 10; s.end = 400; break;
    case KernelMode::linear_step: s.mode = FogMode::linear; s.start = s.end = kStepStart; break;
    case KernelMode::exp: s.mode = FogMode::exp; s.density = 0.01f; break;
    case KernelMode::exp2: s.mode = FogMode::exp2; s.density = 0.005f; break;
    case KernelMode::none: s.mode = FogMode::off; break;
    case KernelMode::height: break;  // its own suite: tests/height_fog_test.cpp
  }
  return s;
}

// Frames are costly at 1080p: make each (size, Z, format) once.
const TestFrame& frame(int w, int h, bool reversed, ColorFormat format) {
  static std::map<std::tuple<int, int, bool, ColorFormat>, TestFrame> cache;
  auto key = std::make_tuple(w, h, reversed, format);
  auto it = cache.find(key);
  if (it == cache.end()) it = cache.emplace(key, make_test_frame(w, h, reversed, format, 1, kStepStart)).first;
  return it->second;
}

using Param = std::tuple<KernelMode, bool /*distance*/, bool /*skybox*/, bool /*reversed*/,
                         ColorFormat, std::pair<int, int>>;

class KernelVsReference : public ::testing::TestWithParam<Param> {};

TEST_P(KernelVsReference, WithinBudget) {
  FOGCL_REQUIRE_DEVICE();
  const auto [mode, distance, skybox, reversed, format, size] = GetParam();
  // A variable of its own (lambdas may not capture structured bindings before C++20).
  const bool f32 = format == ColorFormat::rgba32f;
  const TestFrame& t = frame(size.first, size.second, reversed, format);
  const FogSettings s = settings_for(mode, distance, skybox);

  ColorImage scalar_out;
  apply_fog_scalar(t.color, t.depth, scalar_out, t.params, s);
  const FogResult<double> ref = fog_scalar<double>(t.color, t.depth, t.params, s);
  const ErrorStats c = compare_color(scalar_out, ref, t.color, s.color);
  // Fog factor, through a probe run that makes each channel equal to f (f32 storage only; half
  // storage would round f itself).
  FogSettings probe = s;
  probe.color = glm::vec3(0.0f);
  const ColorImage white = f32 ? white_like(t.color) : ColorImage();
  std::optional<FogResult<double>> fref;
  double cf = 0;
  if (f32) {
    ColorImage cp;
    apply_fog_scalar(white, t.depth, cp, t.params, probe);
    fref = fog_scalar<double>(white, t.depth, t.params, probe);
    cf = factor_error(cp, *fref);
  }
  // One path's errors (color against the reference, fog factor) within the budgets.
  const auto expect_within_budget = [&](const ErrorStats& e, double factor_err, const char* path) {
    EXPECT_EQ(e.nonfinite_from_finite, 0u) << path;
    EXPECT_EQ(e.alpha_changed, 0u) << path;
    EXPECT_LE(factor_err, kFactorBudget) << path;
    if (f32)
      EXPECT_LE(e.max_rel, kColorRelBudget) << path;
    else
      EXPECT_LE(e.max_half_ulps_beyond_factor, kHalfUlpBudget) << path;
  };
  expect_within_budget(c, cf, "scalar<float>");

  // Every kernel path: on CPU devices the blocks and the GPUs' one-pixel kernel (up to 333x211:
  // its vector accesses and row handling, not PoCL's speed at 1080p), on GPUs their kernel.
  for (const KernelPath& path : kernel_paths()) {
    if (!path.is_cpu_blocks && runtime()->is_cpu() && size.first > 1000) continue;
    FogPass& pass = *path.pass;
    ColorImage kernel_out;
    pass.apply(t.color, t.depth, kernel_out, t.params, s);
    ASSERT_EQ(pass.last_variant().mode, mode);
    const ErrorStats k = compare_color(kernel_out, ref, t.color, s.color);
    double kf = 0;
    if (fref) {
      ColorImage kp;
      pass.apply(white, t.depth, kp, t.params, probe);
      kf = factor_error(kp, *fref);
    }
    std::printf("[ worst    ] %-46s %-9s %4dx%-4d kernel: f %.2e rel %.2e ulp16 %.2f | scalar<float>: f %.2e rel %.2e ulp16 %.2f\n",
                describe(pass.last_variant()).c_str(), path.name, size.first, size.second, kf, k.max_rel,
                k.max_ulps, cf, c.max_rel, c.max_ulps);
    expect_within_budget(k, kf, path.name);
  }
}

std::string name(const ::testing::TestParamInfo<Param>& info) {
  const auto [mode, distance, skybox, reversed, format, size] = info.param;
  std::string n = to_string(mode);
  for (char& ch : n)
    if (ch == '-') ch = '_';
  n += distance ? "_distance" : "_depth";
  n += skybox ? "_fogsky" : "_skytest";
  n += reversed ? "_revz" : "_convz";
  n += format == ColorFormat::rgba16f ? "_f16_" : "_f32_";
  return n + std::to_string(size.first) + "x" + std::to_string(size.second);
}

INSTANTIATE_TEST_SUITE_P(
    AllVariants, KernelVsReference,
    ::testing::Combine(::testing::Values(KernelMode::linear, KernelMode::linear_step, KernelMode::exp,
                                         KernelMode::exp2),
                       ::testing::Bool(), ::testing::Bool(), ::testing::Bool(),
                       ::testing::Values(ColorFormat::rgba32f, ColorFormat::rgba16f),
                       ::testing::Values(std::make_pair(1, 1), std::make_pair(7, 5),
                                         std::make_pair(333, 211), std::make_pair(1920, 1080))),
    name);

}  // namespace
}  // namespace fogcl::test
