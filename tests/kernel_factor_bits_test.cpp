// The kernel on a CPU device runs the formulas of kernels/fog_math.h lane-wise IEEE, like the
// scalar float path, so its fog factors must be the scalar path's bit for bit — with the AVX-512
// builtins (fog_cpu_avx512.h: a real-valued exp2 reduction, vscalefps) and without them (the
// portable OpenCL C path). The probe frame (color 1, fog color 0) makes each output channel equal
// to f. Densities are chosen so that exp2's argument covers its whole domain, including the flush
// below -126 and beyond. KernelOutputBits then checks the whole output (blend, half storage,
// every projection), which `fogcl apply`'s tiering relies on.
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

// The whole output, not only the factor: `fogcl apply` fogs the frames that reach its fog stage
// before PoCL has opened on the scalar path and the rest on the CPU kernel (tiering, apply.cpp),
// which is only right if every byte of the blend (HDR colors, a fog color, half storage, alpha,
// sky) is the same on both. Every mode, metric, sky choice and projection, in both storages, with
// the target's builtins and without.
struct OutputCase {
  FogMode mode;
  FogMetric metric;
  bool fog_skybox;
  Projection projection;
  bool reversed;
  ColorFormat format;
};

std::string output_case_name(const testing::TestParamInfo<OutputCase>& info) {
  const OutputCase& c = info.param;
  std::string n = to_string(c.mode);
  n += c.metric == FogMetric::distance ? "_distance" : "_depth";
  n += c.fog_skybox ? "_fogsky" : "_skytest";
  n += c.projection == Projection::orthographic                ? "_ortho"
       : c.projection == Projection::perspective_infinite_far ? "_infinitefar"
                                                               : "_persp";
  n += c.reversed ? "_reversed" : "_conventional";
  n += std::string("_") + to_string(c.format);
  return n;
}

std::vector<OutputCase> output_cases() {
  std::vector<OutputCase> cases;
  for (ColorFormat format : {ColorFormat::rgba32f, ColorFormat::rgba16f})
    for (FogMode mode : {FogMode::linear, FogMode::exp, FogMode::exp2})
      for (FogMetric metric : {FogMetric::depth, FogMetric::distance}) {
        // Each feature once against the plain case: the sky test, reversed Z, each projection.
        cases.push_back({mode, metric, false, Projection::perspective, false, format});
        cases.push_back({mode, metric, true, Projection::perspective, true, format});
        cases.push_back({mode, metric, false, Projection::orthographic, false, format});
        cases.push_back({mode, metric, false, Projection::perspective_infinite_far, true, format});
      }
  return cases;
}

class KernelOutputBits : public testing::TestWithParam<OutputCase> {
 protected:
  void SetUp() override {
    FOGCL_REQUIRE_DEVICE();
    if (!runtime()->is_cpu())
      GTEST_SKIP() << "bit identity with the scalar path is the CPU kernel's (GPU divisions may round differently)";
  }
};

TEST_P(KernelOutputBits, EqualTheScalarPathBitForBit) {
  const OutputCase& c = GetParam();
  const TestFrame t = make_test_frame(517, 23, c.reversed, c.format, 5);
  CameraParams params = t.params;
  if (c.projection == Projection::orthographic) {
    OrthographicCamera ortho;
    ortho.aspect = t.camera.aspect;
    ortho.near_plane = t.camera.near_plane;
    ortho.far_plane = t.camera.far_plane;
    params = make_camera_params(ortho);
  } else if (c.projection == Projection::perspective_infinite_far) {
    PerspectiveCamera infinite = t.camera;
    infinite.infinite_far = true;
    params = make_camera_params(infinite);
  }
  FogSettings s;
  s.mode = c.mode;
  s.metric = c.metric;
  s.fog_skybox = c.fog_skybox;
  s.color = glm::vec3(0.6f, 0.7f, 0.8f);
  s.start = 2.0f;
  s.end = 400.0f;
  s.density = 0.01f;

  ColorImage scalar, target, portable, streaming;
  apply_fog_scalar(t.color, t.depth, scalar, params, s);
  shared_pass().apply(t.color, t.depth, target, params, s);
  CpuCodegen plain;
  plain.target_intrinsics = false;
  FogPass portable_pass(*runtime(), plain);
  portable_pass.apply(t.color, t.depth, portable, params, s);
  // Non-temporal stores on this small frame (by default they start at frames whose pass traffic is
  // half the last-level cache): the same bits, also in the blocks that a 517-pixel row leaves unaligned.
  CpuCodegen nt;
  nt.streaming_stores = CpuCodegen::Streaming::always;
  FogPass streaming_pass(*runtime(), nt);
  streaming_pass.apply(t.color, t.depth, streaming, params, s);

  // Bytes, so that NaN payloads and -0 count too.
  const auto bytes_off = [&](const ColorImage& got) {
    std::size_t off = 0;
    for (std::size_t i = 0; i < got.size_bytes(); ++i)
      off += static_cast<const unsigned char*>(got.data())[i] != static_cast<const unsigned char*>(scalar.data())[i];
    return off;
  };
  std::size_t changed = 0;  // bytes the fog changed: the comparison covers the blend
  for (std::size_t i = 0; i < scalar.size_bytes(); ++i)
    changed += static_cast<const unsigned char*>(scalar.data())[i] != static_cast<const unsigned char*>(t.color.data())[i];
  const std::size_t target_off = bytes_off(target), portable_off = bytes_off(portable);
  const std::size_t streaming_off = bytes_off(streaming);
  std::printf("[ worst    ] %s: bytes off the scalar path: target %zu, portable %zu, streaming stores %zu "
              "(of %zu, %zu fogged)\n",
              output_case_name({c, 0}).c_str(), target_off, portable_off, streaming_off, scalar.size_bytes(), changed);
  EXPECT_EQ(target_off, 0u);
  EXPECT_EQ(portable_off, 0u);
  EXPECT_EQ(streaming_off, 0u);
  EXPECT_GT(changed, scalar.size_bytes() / 8);
}

INSTANTIATE_TEST_SUITE_P(Variants, KernelOutputBits, testing::ValuesIn(output_cases()), output_case_name);

}  // namespace
}  // namespace fogcl::test
