// The kernel on a CPU device runs the formulas of kernels/fog_math.h lane-wise IEEE, like the
// scalar float path, so its fog factors must be the scalar path's bit for bit — with the AVX-512
// builtins (fog_cpu_avx512.h: a real-valued exp2 reduction, vscalefps) and without them (the
// portable OpenCL C path). The probe frame (color 1, fog color 0) makes each output channel equal
// to f. Densities are chosen so that exp2's argument covers its whole domain, including the flush
// below -126 and beyond.
#include <cmath>
#include <cstring>
#include <vector>

#include "test_support.h"

namespace fogcl::test {
namespace {

struct FactorCase {
  FogMode mode;
  FogMetric metric;
  bool reversed;
  float reach;  // exp / exp2: the exponent's magnitude at the far plane; linear: end / far
};

std::string name_of(const testing::TestParamInfo<FactorCase>& info) {
  const FactorCase& c = info.param;
  std::string n = to_string(c.mode);
  n += c.metric == FogMetric::distance ? "_distance" : "_depth";
  n += c.reversed ? "_reversed" : "_conventional";
  n += "_reach" + std::to_string(int(c.reach * 100));
  return n;
}

std::vector<FactorCase> all_cases() {
  std::vector<FactorCase> cases;
  for (FogMetric metric : {FogMetric::depth, FogMetric::distance})
    for (bool reversed : {false, true}) {
      for (float reach : {0.3f, 0.9f}) cases.push_back({FogMode::linear, metric, reversed, reach});
      for (FogMode m : {FogMode::exp, FogMode::exp2})
        for (float reach : {0.5f, 20.0f, 140.0f, 1e4f}) cases.push_back({m, metric, reversed, reach});
    }
  return cases;
}

class KernelFactorBits : public testing::TestWithParam<FactorCase> {
 protected:
  void SetUp() override {
    FOGCL_REQUIRE_DEVICE();
    if (!runtime()->is_cpu())
      GTEST_SKIP() << "bit identity with the scalar path is the CPU kernel's (GPU divisions may round differently)";
  }

  FogSettings settings(float far_plane) const {
    const FactorCase& c = GetParam();
    FogSettings s;
    s.mode = c.mode;
    s.metric = c.metric;
    s.color = glm::vec3(0.0f);
    s.start = 0.05f * far_plane;
    s.end = c.reach * far_plane;
    const float log2e = 1.4426950408889634f;
    // exp: x = -d density log2(e); exp2: x = -(d density)^2 log2(e). |x| = reach at d = far.
    s.density = c.mode == FogMode::exp ? c.reach / (far_plane * log2e)
                                       : std::sqrt(c.reach / log2e) / far_plane;
    return s;
  }
};

std::uint32_t bits_of(float v) {
  std::uint32_t b;
  std::memcpy(&b, &v, 4);
  return b;
}

TEST_P(KernelFactorBits, EqualTheScalarPathBitForBit) {
  const TestFrame t = make_test_frame(1021, 40, GetParam().reversed, ColorFormat::rgba32f, 11);
  const ColorImage white = white_like(t.color);
  const FogSettings s = settings(t.params.projection_params.z);
  const FogResult<float> scalar = fog_scalar<float>(white, t.depth, t.params, s);

  ColorImage target, portable;
  shared_pass().apply(white, t.depth, target, t.params, s);
  CpuCodegen plain;
  plain.target_intrinsics = false;
  FogPass portable_pass(*runtime(), plain);
  portable_pass.apply(white, t.depth, portable, t.params, s);

  std::size_t target_off = 0, portable_off = 0, between = 0, zeros = 0;
  float first_bad = 0, first_bad_ref = 0;
  for (std::size_t i = 0; i < t.depth.pixel_count(); ++i) {
    const float f = scalar.factor[i];
    between += f > 0.0f && f < 1.0f;
    zeros += f == 0.0f;
    for (int ch = 0; ch < 3; ++ch) {
      const float a = target.rgba32f()[4 * i + ch], b = portable.rgba32f()[4 * i + ch];
      if (bits_of(a) != bits_of(f)) {
        if (target_off++ == 0) first_bad = a, first_bad_ref = f;
      }
      portable_off += bits_of(b) != bits_of(f);
    }
  }
  std::printf("[ worst    ] %s: %zu pixels 0 < f < 1, %zu f == 0; channels off the scalar path: "
              "target %zu, portable %zu\n",
              name_of({GetParam(), 0}).c_str(), between, zeros, target_off, portable_off);
  EXPECT_EQ(target_off, 0u) << "first: kernel " << first_bad << " scalar " << first_bad_ref;
  EXPECT_EQ(portable_off, 0u);
  EXPECT_GT(between, std::size_t(5000));  // the comparison covers the formula, not only 0 and 1
  if (GetParam().reach >= 140.0f) {
    EXPECT_GT(zeros, std::size_t(100));  // and exp2's flush
  }
}

INSTANTIATE_TEST_SUITE_P(Variants, KernelFactorBits, testing::ValuesIn(all_cases()), name_of);

}  // namespace
}  // namespace fogcl::test
