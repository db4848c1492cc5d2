// The CPU kernel fogs 16 pixels at a time and picks one of four blends per block (all f == 1:
// copy; all f == 0: fog color; no lane 0 or 1: the formula alone; mixed: per lane, then the
// f == 1 half pixels copied over). These tests build frames that take every one of them, check
// the blend rules pixel by pixel, and check that the portable OpenCL C path (what CPUs without
// AVX-512 run) writes the same bytes as the path with target builtins.
#include <cstring>
#include <limits>
#include <vector>

#include "test_support.h"

namespace fogcl::test {
namespace {

struct BlockCase {
  FogMode mode;
  FogMetric metric;
  bool skybox;
  bool reversed;
  ColorFormat format;
};

std::string name_of(const testing::TestParamInfo<BlockCase>& info) {
  const BlockCase& c = info.param;
  std::string n = to_string(c.mode);
  n += c.metric == FogMetric::distance ? "_distance" : "_depth";
  n += c.skybox ? "_skybox" : "_skytest";
  n += c.reversed ? "_reversed" : "_conventional";
  n += c.format == ColorFormat::rgba16f ? "_f16" : "_f32";
  return n;
}

std::vector<BlockCase> all_cases() {
  std::vector<BlockCase> cases;
  for (FogMode m : {FogMode::linear, FogMode::exp, FogMode::exp2})
    for (FogMetric metric : {FogMetric::depth, FogMetric::distance})
      for (bool skybox : {false, true})
        for (bool reversed : {false, true})
          for (ColorFormat f : {ColorFormat::rgba32f, ColorFormat::rgba16f})
            cases.push_back({m, metric, skybox, reversed, f});
  return cases;
}

class CpuBlockPaths : public testing::TestWithParam<BlockCase> {
 protected:
  void SetUp() override {
    FOGCL_REQUIRE_DEVICE();
    if (!runtime()->is_cpu()) GTEST_SKIP() << "the block paths are the CPU kernel's";
  }

  // 333 x 64 (20 blocks and a 13-pixel tail per row): rows 0-7 sky, 8-15 at distance 0 (f = 1),
  // 16-23 just before the far plane (f = 0 in linear fog ending at 50 and in dense exp fog), the
  // rest the random depths of make_test_frame; every 5th pixel a color that stresses the rules.
  TestFrame frame() const {
    const BlockCase& c = GetParam();
    TestFrame t = make_test_frame(333, 64, c.reversed, c.format, 7);
    const float sky = c.reversed ? 0.0f : 1.0f, at_near = c.reversed ? 1.0f : 0.0f;
    const float almost_far = c.reversed ? 1e-6f : 1.0f - 1e-6f;
    for (int y = 0; y < 24; ++y)
      for (int x = 0; x < t.depth.width(); ++x) t.depth.at(x, y) = y < 8 ? sky : y < 16 ? at_near : almost_far;
    const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
    const float specials[] = {nan, inf, -inf, 65504.0f, -0.0f, 3.0e38f};
    int n = 0;
    for (int y = 0; y < t.color.height(); ++y)
      for (int x = 0; x < t.color.width(); x += 5, ++n) {
        const float v = specials[n % 6];
        if (t.color.format() == ColorFormat::rgba16f && std::fabs(v) > 65504.0f && std::isfinite(v)) continue;
        t.color.set_pixel(x, y, glm::vec4(v, 0.5f, v, n % 2 ? v : -0.0f));
      }
    // Signalling NaNs with payloads: the f == 1 pixels must keep these bits.
    for (int y = 0; y < t.color.height(); y += 3) {
      const std::size_t i = 4 * (std::size_t(y) * t.color.width() + std::size_t(y % 16));
      if (t.color.format() == ColorFormat::rgba16f) {
        t.color.rgba16f()[i] = 0x7d01;
        t.color.rgba16f()[i + 3] = 0xfd02;
      } else {
        const std::uint32_t snan = 0x7fa00001u;
        std::memcpy(&t.color.rgba32f()[i], &snan, 4);
        std::memcpy(&t.color.rgba32f()[i + 3], &snan, 4);
      }
    }
    return t;
  }

  FogSettings settings() const {
    const BlockCase& c = GetParam();
    FogSettings s;
    s.mode = c.mode;
    s.metric = c.metric;
    s.fog_skybox = c.skybox;
    s.start = 0.5f;
    s.end = 50.0f;
    s.density = c.mode == FogMode::exp ? 0.5f : 0.08f;
    s.color = glm::vec3(0.62f, 0.68f, 0.76f);
    return s;
  }
};

const std::byte* pixel_bytes(const ColorImage& img, std::size_t i) {
  return static_cast<const std::byte*>(img.data()) + i * bytes_per_pixel(img.format());
}

TEST_P(CpuBlockPaths, FollowTheBlendRulesAndMatchThePortablePath) {
  const TestFrame t = frame();
  const FogSettings s = settings();
  ColorImage target, portable;
  shared_pass().apply(t.color, t.depth, target, t.params, s);
  CpuCodegen plain;
  plain.target_intrinsics = false;
  FogPass portable_pass(*runtime(), plain);
  portable_pass.apply(t.color, t.depth, portable, t.params, s);

  // f of every pixel from the scalar float path: the same formulas, the same exp2 polynomial.
  const FogResult<float> f32 = fog_scalar<float>(t.color, t.depth, t.params, s);
  const std::size_t bpp = bytes_per_pixel(t.color.format());
  std::size_t ones = 0, zeros = 0, differing = 0, rule_breaks = 0;
  ColorImage fog_pixel(1, 1, t.color.format());
  for (std::size_t i = 0; i < t.depth.pixel_count(); ++i) {
    if (std::memcmp(pixel_bytes(target, i), pixel_bytes(portable, i), bpp) != 0) ++differing;
    const int x = int(i % t.color.width()), y = int(i / t.color.width());
    if (f32.factor[i] == 1.0f) {
      ++ones;
      if (std::memcmp(pixel_bytes(target, i), pixel_bytes(t.color, i), bpp) != 0) ++rule_breaks;
    } else if (f32.factor[i] == 0.0f) {
      ++zeros;
      // RGB exactly the fog color (stored), alpha the input's bits (docs/accuracy.md: a NaN alpha of a
      // fogged half pixel may be quieted).
      fog_pixel.set_pixel(0, 0, glm::vec4(s.color, t.color.pixel(x, y).a));
      const std::size_t channel = bpp / 4;
      const float alpha_in = t.color.pixel(x, y).a, alpha_out = target.pixel(x, y).a;
      const bool alpha_kept =
          std::memcmp(pixel_bytes(target, i) + 3 * channel, pixel_bytes(t.color, i) + 3 * channel, channel) == 0 ||
          (t.color.format() == ColorFormat::rgba16f && std::isnan(alpha_in) && std::isnan(alpha_out));
      if (std::memcmp(pixel_bytes(target, i), fog_pixel.data(), 3 * channel) != 0 || !alpha_kept) ++rule_breaks;
    }
  }
  // Between 0 and 1 the kernel's color stays within 1e-6 relative (measured 1.9e-7) and one half
  // ulp beyond the factor budget (measured 0.50), alpha passes through.
  const ErrorStats e = compare_color(target, fog_scalar<double>(t.color, t.depth, t.params, s), t.color, s.color);
  std::printf("[ worst    ] %s: %zu pixels f == 1, %zu f == 0; rule breaks %zu; bytes differing from the portable path %zu; "
              "rel %.2e, half ulps beyond the factor %.2f, alpha changed %zu\n",
              name_of({GetParam(), 0}).c_str(), ones, zeros, rule_breaks, differing, e.max_rel,
              e.max_half_ulps_beyond_factor, e.alpha_changed);
  if (!GetParam().skybox) {  // the sky rows: all-f == 1 blocks
    EXPECT_GT(ones, std::size_t(8 * 333));
  }
  if (GetParam().mode == FogMode::linear || GetParam().mode == FogMode::exp) {
    EXPECT_GT(zeros, std::size_t(8 * 300));
  }
  EXPECT_EQ(rule_breaks, 0u);
  EXPECT_EQ(differing, 0u);
  EXPECT_EQ(e.nonfinite_from_finite, 0u);
  EXPECT_EQ(e.alpha_changed, 0u);
  if (t.color.format() == ColorFormat::rgba32f)
    EXPECT_LE(e.max_rel, 1e-6);
  else
    EXPECT_LE(e.max_half_ulps_beyond_factor, 1.0);
}

INSTANTIATE_TEST_SUITE_P(Variants, CpuBlockPaths, testing::ValuesIn(all_cases()), name_of);

}  // namespace
}  // namespace fogcl::test
