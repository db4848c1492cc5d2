// Blend and NaN rules of docs/DESIGN.md §2 on the kernel and the scalar path, f32 and f16 storage:
// f == 1 leaves the pixel bit-exact, f == 0 writes exactly the fog color, alpha passes through,
// a NaN at 0 < f < 1 stays in its channel, finite input never gives non-finite output, and fog
// off / density 0 dispatch nothing and copy bit for bit.
#include <cmath>
#include <cstring>
#include <limits>

#include "test_support.h"

namespace fogcl::test {
namespace {

// One camera for frames of any shape (probes of a few pixels, 8K frames): the aspect check of
// the passes is stated off (CameraParams::non_square_pixels).
template <class Camera>
CameraParams params_any_frame(const Camera& camera) {
  CameraParams p = make_camera_params(camera);
  p.non_square_pixels = true;
  return p;
}

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kMax = std::numeric_limits<float>::max();

struct Path {
  bool scalar;
  ColorFormat format;
  Precision precision = Precision::precise;
};

void PrintTo(const Path& p, std::ostream* os) {
  *os << (p.scalar ? "scalar " : "kernel ") << to_string(p.format) << " " << to_string(p.precision);
}

class BlendRules : public ::testing::TestWithParam<Path> {
 protected:
  void SetUp() override {
    if (!GetParam().scalar && runtime() == nullptr) GTEST_SKIP() << "no OpenCL device: " << runtime_error();
  }
  // The fast variants (-cl-fast-relaxed-math implies -cl-finite-math-only, which lets the
  // compiler assume no NaN/Inf) must keep the same rules: the blend decides on f only.
  ColorImage run(const ColorImage& in, const DepthImage& depth, const CameraParams& cam, FogSettings s) {
    s.precision = GetParam().precision;
    ColorImage out;
    if (GetParam().scalar)
      apply_fog_scalar(in, depth, out, cam, s);
    else
      shared_pass().apply(in, depth, out, cam, s);
    return out;
  }
  // Colors that stress the blend: NaN, +-Inf, beyond half max, float max, a signalling-NaN bit
  // pattern (f32 only) and ordinary values.
  ColorImage stress_colors() const {
    const float values[] = {kNaN, kInf, -kInf, 70000.0f, 65504.0f, 1.0f, 0.25f, -2.0f, kMax, -kMax};
    const int n = int(std::size(values));
    ColorImage img(n, n, GetParam().format);
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) img.set_pixel(x, y, glm::vec4(values[x], values[y], 0.5f, values[(x + y) % n]));
    if (GetParam().format == ColorFormat::rgba32f) {
      const std::uint32_t snan = 0x7fa00001u;  // signalling NaN with a payload
      std::memcpy(&img.rgba32f()[0], &snan, 4);
      std::memcpy(&img.rgba32f()[3], &snan, 4);
    } else {
      img.rgba16f()[0] = 0x7d01;  // signalling half NaN with a payload
    }
    return img;
  }
};

bool same_pixel_bits(const ColorImage& a, const ColorImage& b, int x, int y, int first = 0, int count = 4) {
  const std::size_t bpc = bytes_per_pixel(a.format()) / 4;
  const std::size_t off = (std::size_t(y) * a.width() + x) * 4 * bpc + first * bpc;
  return std::memcmp(static_cast<const std::byte*>(a.data()) + off,
                     static_cast<const std::byte*>(b.data()) + off, count * bpc) == 0;
}

TEST_P(BlendRules, FactorOneIsBitExact) {
  // Every pixel is sky (raw depth at the far plane) and the sky is not fogged: f == 1.
  PerspectiveCamera camera;
  const CameraParams cam = params_any_frame(camera);
  const ColorImage in = stress_colors();
  const DepthImage depth(in.width(), in.height(), 1.0f);
  FogSettings s;
  s.mode = FogMode::exp;
  s.density = 1.0f;
  const ColorImage out = run(in, depth, cam, s);
  for (int y = 0; y < in.height(); ++y)
    for (int x = 0; x < in.width(); ++x) ASSERT_TRUE(same_pixel_bits(in, out, x, y)) << x << "," << y;
}

TEST_P(BlendRules, FactorZeroIsExactlyFogColor) {
  // density * d ~ 1e20 * 100: exp2's argument squares to +inf; f must be exactly 0, not NaN.
  PerspectiveCamera camera;
  const CameraParams cam = params_any_frame(camera);
  const ColorImage in = stress_colors();
  const float raw = float((1000.0 / 100.0 - cam.zbuffer_params.y) / cam.zbuffer_params.x);  // eye depth 100
  const DepthImage depth(in.width(), in.height(), raw);
  for (FogMode mode : {FogMode::exp, FogMode::exp2}) {
    FogSettings s;
    s.mode = mode;
    s.density = 1e20f;
    s.color = glm::vec3(0.1f, 0.2f, 0.3f);
    const ColorImage out = run(in, depth, cam, s);
    const ColorImage fog = [&] {
      ColorImage f(1, 1, in.format());
      f.set_pixel(0, 0, glm::vec4(s.color, 0.0f));
      return f;
    }();
    for (int y = 0; y < in.height(); ++y)
      for (int x = 0; x < in.width(); ++x) {
        const glm::vec4 o = out.pixel(x, y);
        for (int c = 0; c < 3; ++c) ASSERT_EQ(o[c], fog.pixel(0, 0)[c]) << to_string(mode) << " " << x << "," << y;
        // Alpha passes through (bit-exact in f32; f16 alpha goes through float when f < 1, so
        // only its value is kept, and a NaN stays NaN).
        if (in.format() == ColorFormat::rgba32f)
          ASSERT_TRUE(same_pixel_bits(in, out, x, y, 3, 1)) << x << "," << y;
        else if (std::isnan(in.pixel(x, y).a))
          ASSERT_TRUE(std::isnan(o.a));
        else
          ASSERT_EQ(o.a, in.pixel(x, y).a);
      }
  }
}

TEST_P(BlendRules, PartialFogKeepsNaNInItsChannelAndFiniteStaysFinite) {
  PerspectiveCamera camera;
  const CameraParams cam = params_any_frame(camera);
  const ColorImage in = stress_colors();
  const float raw = float((1000.0 / 100.0 - cam.zbuffer_params.y) / cam.zbuffer_params.x);
  const DepthImage depth(in.width(), in.height(), raw);
  FogSettings s;
  s.mode = FogMode::linear;
  s.start = 0.0f;
  s.end = 200.0f;  // f ~ 0.5 at eye depth 100
  s.color = glm::vec3(65504.0f, 0.0f, 1.0f);
  const ColorImage out = run(in, depth, cam, s);
  std::size_t nonfinite_from_finite = 0;
  for (int y = 0; y < in.height(); ++y)
    for (int x = 0; x < in.width(); ++x) {
      const glm::vec4 c = in.pixel(x, y), o = out.pixel(x, y);
      for (int ch = 0; ch < 3; ++ch) {
        if (std::isnan(c[ch])) {
          EXPECT_TRUE(std::isnan(o[ch])) << x << "," << y << " ch " << ch;
        }
        if (std::isinf(c[ch]) && GetParam().format == ColorFormat::rgba32f) {
          EXPECT_EQ(o[ch], c[ch]);
        }
        // Half storage: a finite value above 65504 rounds to Inf when stored; that is the
        // storage's range, not the blend (the input itself is already Inf there).
        if (std::isfinite(c[ch]) && !std::isfinite(o[ch])) ++nonfinite_from_finite;
      }
    }
  EXPECT_EQ(nonfinite_from_finite, 0u);
}

TEST_P(BlendRules, NaNAndOutOfRangeDepth) {
  // NaN depth is the far end (sky): f == 1 with the sky test. Depth outside [0, 1] is clamped.
  for (bool reversed : {false, true}) {
    PerspectiveCamera camera;
    camera.reversed_z = reversed;
    const CameraParams cam = params_any_frame(camera);
    ColorImage in(4, 1, GetParam().format);
    for (int x = 0; x < 4; ++x) in.set_pixel(x, 0, glm::vec4(1.0f));
    DepthImage depth(4, 1);
    depth.at(0, 0) = kNaN;
    depth.at(1, 0) = reversed ? -5.0f : 7.0f;  // beyond far -> far (sky)
    depth.at(2, 0) = reversed ? 9.0f : -3.0f;  // before near -> near
    depth.at(3, 0) = reversed ? 1.0f : 0.0f;   // exactly near
    FogSettings s;
    s.mode = FogMode::exp;
    s.density = 0.5f;
    s.color = glm::vec3(0.0f);
    const ColorImage out = run(in, depth, cam, s);
    EXPECT_EQ(out.pixel(0, 0).r, 1.0f) << "NaN depth is sky";
    EXPECT_EQ(out.pixel(1, 0).r, 1.0f) << "beyond far is sky";
    EXPECT_EQ(out.pixel(2, 0).r, out.pixel(3, 0).r) << "before near clamps to near";
    // Fogging the skybox: NaN depth is the far plane, fully fogged at density 0.5.
    s.fog_skybox = true;
    const ColorImage sky = run(in, depth, cam, s);
    EXPECT_EQ(sky.pixel(0, 0).r, 0.0f);
    EXPECT_TRUE(std::isfinite(sky.pixel(2, 0).r));
  }
}

TEST_P(BlendRules, OffAndZeroDensityCopyBitForBit) {
  PerspectiveCamera camera;
  const CameraParams cam = params_any_frame(camera);
  const ColorImage in = stress_colors();
  const DepthImage depth(in.width(), in.height(), 0.5f);
  const std::size_t dispatches = GetParam().scalar ? 0 : shared_pass().stats().kernel_dispatches;
  FogSettings off;
  off.mode = FogMode::off;
  FogSettings zero;
  zero.mode = FogMode::exp2;
  zero.density = 0.0f;
  for (const FogSettings& s : {off, zero}) {
    const ColorImage out = run(in, depth, cam, s);
    ASSERT_EQ(std::memcmp(in.data(), out.data(), in.size_bytes()), 0) << to_string(s.mode);
  }
  if (!GetParam().scalar) {
    EXPECT_EQ(shared_pass().stats().kernel_dispatches, dispatches) << "fog off dispatched a kernel";
  }
}

INSTANTIATE_TEST_SUITE_P(Paths, BlendRules,
                         ::testing::Values(Path{false, ColorFormat::rgba32f}, Path{false, ColorFormat::rgba16f},
                                           Path{true, ColorFormat::rgba32f}, Path{true, ColorFormat::rgba16f},
                                           Path{false, ColorFormat::rgba32f, Precision::fast},
                                           Path{false, ColorFormat::rgba16f, Precision::fast}),
                         [](const auto& info) {
                           return std::string(info.param.scalar ? "scalar_" : "kernel_") + to_string(info.param.format) +
                                  "_" + to_string(info.param.precision);
                         });

}  // namespace
}  // namespace fogcl::test
