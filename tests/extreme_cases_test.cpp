// Stiff and extreme cases (issue: numerical stability), each with its expected behaviour stated:
// hard-step linear fog, zero and enormous optical depths, thin fog, huge far/near ratios,
// reversed Z with an infinite far plane, orthographic cameras, odd and huge image sizes.
// Kernel and scalar paths are both held to the float64 path.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>
#include <random>

#include "pass/formulas.h"
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

constexpr double kFactorBudget = 2e-6;
constexpr double kColorRelBudget = 1e-5;

using RawFromEye = std::function<double(double eye)>;

// Raw depth of an eye depth for each projection (the inverse of the kernel's mapping, in double).
RawFromEye raw_from_eye(const CameraParams& cam) {
  const double n = cam.near_plane(), f = cam.far_plane();
  const double zx = cam.zbuffer_params.x, zy = cam.zbuffer_params.y;
  switch (cam.projection) {
    case Projection::perspective_infinite_far: return [n](double eye) { return n / eye; };
    case Projection::orthographic: return [zx, zy, f](double eye) { return (eye / f - zy) / zx; };
    case Projection::perspective: break;
  }
  return [zx, zy, f](double eye) { return (f / eye - zy) / zx; };
}

// Random HDR colors; eye depths log-uniform in [near, max_eye]; `sky_share` of pixels at the sky
// raw value (1 conventional, 0 reversed).
TestFrame frame_for(const CameraParams& cam, int w, int h, ColorFormat format, double max_eye,
                    double sky_share = 0.1, double min_eye = 0.0, unsigned seed = 5) {
  TestFrame t;
  t.params = cam;
  t.color = ColorImage(w, h, format);
  t.depth = DepthImage(w, h);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const RawFromEye raw = raw_from_eye(cam);
  const double n = std::max({double(cam.near_plane()), 1e-3, min_eye});
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      t.color.set_pixel(x, y, glm::vec4(4 * unit(rng), 4 * unit(rng), 4 * unit(rng), unit(rng)));
      const double eye = n * std::pow(max_eye / n, unit(rng));
      t.depth.at(x, y) = unit(rng) < sky_share ? (cam.reversed_z ? 0.0f : 1.0f) : float(raw(eye));
    }
  return t;
}

ColorImage run(bool scalar, const ColorImage& in, const DepthImage& depth, const CameraParams& cam,
               const FogSettings& s) {
  ColorImage out;
  if (scalar)
    apply_fog_scalar(in, depth, out, cam, s);
  else
    shared_pass().apply(in, depth, out, cam, s);
  return out;
}

struct Budgets {
  double factor, color_rel;
};

// Kernel and scalar float against the double path: color, and the fog factor through a probe run.
Budgets check_against_double(bool scalar, const TestFrame& t, const FogSettings& s) {
  const ColorImage out = run(scalar, t.color, t.depth, t.params, s);
  const FogResult<double> ref = fog_scalar<double>(t.color, t.depth, t.params, s);
  const ErrorStats e = compare_color(out, ref, t.color, s.color);
  EXPECT_EQ(e.nonfinite_from_finite, 0u);
  EXPECT_EQ(e.alpha_changed, 0u);
  FogSettings probe = s;
  probe.color = glm::vec3(0.0f);
  const ColorImage white = white_like(convert(t.color, ColorFormat::rgba32f));
  const double fe = factor_error(run(scalar, white, t.depth, t.params, probe),
                                 fog_scalar<double>(white, t.depth, t.params, probe));
  return {fe, e.max_rel};
}

std::vector<FogSettings> every_mode(FogMetric metric, bool skybox) {
  std::vector<FogSettings> out;
  for (FogMode m : {FogMode::linear, FogMode::exp, FogMode::exp2}) {
    FogSettings s;
    s.mode = m;
    s.start = 5.0f;
    s.end = 500.0f;
    s.density = m == FogMode::exp ? 0.004f : 0.002f;
    s.metric = metric;
    s.fog_skybox = skybox;
    s.color = glm::vec3(0.5f, 0.6f, 0.7f);
    out.push_back(s);
  }
  FogSettings step = out[0];
  step.end = step.start = 40.0f;
  out.push_back(step);
  return out;
}

class Extreme : public ::testing::TestWithParam<bool /*scalar*/> {
 protected:
  void SetUp() override {
    if (!GetParam() && runtime() == nullptr) GTEST_SKIP() << "no OpenCL device: " << runtime_error();
  }
  bool scalar() const { return GetParam(); }
};

// 1. start == end: 1 before start, 0 from start on, exactly; no NaN. start > end: an error.
TEST_P(Extreme, LinearStartEqualsEndIsAHardStep) {
  const CameraParams cam = params_any_frame(PerspectiveCamera{});
  FogSettings s;
  s.mode = FogMode::linear;
  s.start = s.end = 50.0f;
  s.color = glm::vec3(0.25f, 0.5f, 0.75f);
  const double eyes[] = {1.0, 30.0, 49.0, 51.0, 80.0, 999.0};  // depth-based d = eye - near
  ColorImage in(6, 1);
  DepthImage depth(6, 1);
  for (int x = 0; x < 6; ++x) {
    in.set_pixel(x, 0, glm::vec4(std::numeric_limits<float>::quiet_NaN(), 2.0f, 3.0f, 1.0f));
    depth.at(x, 0) = float(raw_from_eye(cam)(eyes[x]));
  }
  const ColorImage out = run(scalar(), in, depth, cam, s);
  for (int x = 0; x < 6; ++x) {
    const glm::vec4 o = out.pixel(x, 0);
    if (eyes[x] - 0.3 < 50.0) {
      EXPECT_TRUE(std::isnan(o.r)) << x;  // f == 1: the pixel, NaN included, is untouched
      EXPECT_EQ(o.g, 2.0f) << x;
    } else {
      EXPECT_EQ(o.r, 0.25f) << x;  // f == 0: exactly the fog color, the NaN does not leak
      EXPECT_EQ(o.g, 0.5f) << x;
    }
  }
  s.start = 60.0f;
  EXPECT_THROW(run(scalar(), in, depth, cam, s), Error);
}

// 2. Density 0 at any distance, even with an infinite far plane: f == 1, output == input.
TEST_P(Extreme, ZeroDensityIsTheIdentityEvenAtInfinity) {
  PerspectiveCamera pc;
  pc.reversed_z = pc.infinite_far = true;
  const CameraParams cam = params_any_frame(pc);
  const TestFrame t = frame_for(cam, 37, 11, ColorFormat::rgba32f, 1e12, 0.3);
  const std::size_t dispatches = scalar() ? 0 : shared_pass().stats().kernel_dispatches;
  for (FogMode m : {FogMode::exp, FogMode::exp2}) {
    FogSettings s;
    s.mode = m;
    s.density = 0.0f;
    s.fog_skybox = true;
    const ColorImage out = run(scalar(), t.color, t.depth, cam, s);
    EXPECT_EQ(std::memcmp(out.data(), t.color.data(), out.size_bytes()), 0) << to_string(m);
  }
  if (!scalar()) {
    EXPECT_EQ(shared_pass().stats().kernel_dispatches, dispatches);
  }
}

// 3. density * d of 1e3 and 1e20: f is exactly 0 (the fog color), never NaN after squaring.
TEST_P(Extreme, HugeOpticalDepthIsExactlyFogColor) {
  const CameraParams cam = params_any_frame(PerspectiveCamera{});
  const float eye = 100.3f;  // d = 100 (depth-based)
  ColorImage in(2, 1);
  in.set_pixel(0, 0, glm::vec4(1.0f, 2.0f, 3.0f, 0.5f));
  in.set_pixel(1, 0, glm::vec4(std::numeric_limits<float>::infinity(), -7.0f, 1e30f, 0.5f));
  const DepthImage depth(2, 1, float(raw_from_eye(cam)(eye)));
  for (double optical : {1e3, 1e20})
    for (FogMode m : {FogMode::exp, FogMode::exp2}) {
      FogSettings s;
      s.mode = m;
      s.density = float(optical / 100.0);
      s.color = glm::vec3(0.1f, 0.2f, 0.3f);
      const ColorImage out = run(scalar(), in, depth, cam, s);
      const FogResult<double> ref = fog_scalar<double>(in, depth, cam, s);
      for (int x = 0; x < 2; ++x) {
        EXPECT_EQ(out.pixel(x, 0), glm::vec4(0.1f, 0.2f, 0.3f, 0.5f)) << optical << " " << to_string(m);
        EXPECT_EQ(ref.factor[x], 0.0) << "double path";
      }
    }
}

// 4. Thin fog: density * d = 1e-8. f rounds to 1 in float, but the reported fog amount 1 - f is
// density * d to 1e-6 relative (expm1, not a cancellation).
TEST_P(Extreme, ThinFogAmountKeepsItsRelativePrecision) {
  if (!scalar()) GTEST_SKIP() << "the fog amount is reported by the scalar path";
  const CameraParams cam = params_any_frame(PerspectiveCamera{});
  // Eye depths from 10 on: right at the near plane d = L * far - near itself cancels in float.
  const TestFrame t = frame_for(cam, 64, 16, ColorFormat::rgba32f, 900.0, 0.0, 10.0);
  for (FogMode m : {FogMode::exp, FogMode::exp2}) {
    FogSettings s;
    s.mode = m;
    // exp: density * d ~ 1e-8 at d ~ 100; exp2: (density * d)^2 ~ 1e-8.
    s.density = m == FogMode::exp ? 1e-10f : 1e-6f;
    const FogResult<float> f32 = fog_scalar<float>(t.color, t.depth, cam, s);
    const FogResult<double> f64 = fog_scalar<double>(t.color, t.depth, cam, s);
    double worst = 0;
    for (std::size_t i = 0; i < f32.amount.size(); ++i) {
      ASSERT_GT(f64.amount[i], 0.0);
      worst = std::max(worst, std::fabs(double(f32.amount[i]) - f64.amount[i]) / f64.amount[i]);
    }
    std::printf("[ worst    ] thin %s fog: amount 1-f relative error %.2e (float f = %.9g)\n", to_string(m),
                worst, double(f32.factor[0]));
    EXPECT_LE(worst, 1e-6);
  }
}

// 5. Conventional Z with near 0.01, far 1e6: depth 1.0 is sky, one ulp below is not, both finite.
// Eye depth recovered from a float depth buffer, against the true eye depth: reversed Z within
// 1e-6 relative over the whole range; conventional Z is printed (it is the textbook failure).
TEST_P(Extreme, HugeFarNearRatio) {
  for (bool reversed : {false, true}) {
    PerspectiveCamera pc;
    pc.near_plane = 0.01f;
    pc.far_plane = 1e6f;
    pc.reversed_z = reversed;
    const CameraParams cam = params_any_frame(pc);
    ColorImage in(2, 1);
    in.set_pixel(0, 0, glm::vec4(1.0f, 2.0f, 3.0f, 1.0f));
    in.set_pixel(1, 0, glm::vec4(1.0f, 2.0f, 3.0f, 1.0f));
    DepthImage depth(2, 1);
    const float far_raw = reversed ? 0.0f : 1.0f;
    depth.at(0, 0) = far_raw;
    // Conventional: one ulp below 1 is eye depth ~1.4e5, not sky. Reversed: one ulp above 0 is a
    // denormal, still numerically at the far plane; 1e-7 is eye depth ~9e4.
    depth.at(1, 0) = reversed ? 1e-7f : std::nextafter(1.0f, 0.0f);
    FogSettings s;
    s.mode = FogMode::exp;
    s.density = 1e-6f;
    const ColorImage out = run(scalar(), in, depth, cam, s);
    EXPECT_EQ(out.pixel(0, 0), in.pixel(0, 0)) << "depth at the far plane is sky";
    EXPECT_NE(out.pixel(1, 0), in.pixel(1, 0)) << "one ulp nearer is not sky";
    for (int c = 0; c < 4; ++c) EXPECT_TRUE(std::isfinite(out.pixel(1, 0)[c]));

    // Eye depth error of the float path (the kernel's formulas) across the range.
    double worst = 0, worst_at = 0;
    for (double eye = 0.02; eye < 0.99e6; eye *= 1.37) {
      const float raw = float(raw_from_eye(cam)(eye));
      const float l01 = formulas::fog_linear01_depth(raw, cam.zbuffer_params.x, cam.zbuffer_params.y, int(reversed));
      const double err = std::fabs(double(l01) * 1e6 - eye) / eye;
      if (err > worst) worst = err, worst_at = eye;
    }
    std::printf("[ worst    ] near 0.01 far 1e6 %s: eye depth relative error %.2e (at eye %.3g)\n",
                reversed ? "reversed Z" : "conventional Z", worst, worst_at);
    if (reversed) {
      EXPECT_LE(worst, 1e-6);
    }
  }
}

// 6. Reversed Z with an infinite far plane: depth 0 is sky before any arithmetic; every mode,
// depth- and distance-based, within the budgets of the double path.
TEST_P(Extreme, InfiniteFarVariant) {
  PerspectiveCamera pc;
  pc.reversed_z = pc.infinite_far = true;
  pc.aspect = 37.0f / 23.0f;
  const CameraParams cam = params_any_frame(pc);
  const TestFrame t = frame_for(cam, 37, 23, ColorFormat::rgba32f, 1e7, 0.2);
  for (FogMetric metric : {FogMetric::depth, FogMetric::distance})
    for (bool skybox : {false, true})
      for (const FogSettings& s : every_mode(metric, skybox)) {
        const Budgets b = check_against_double(scalar(), t, s);
        EXPECT_LE(b.factor, kFactorBudget) << to_string(s.mode) << " " << to_string(metric);
        EXPECT_LE(b.color_rel, kColorRelBudget) << to_string(s.mode) << " " << to_string(metric);
      }
  // Depth 0: untouched without the skybox, the fog color with it (infinitely far).
  ColorImage in(1, 1);
  in.set_pixel(0, 0, glm::vec4(1.0f, 2.0f, 3.0f, 1.0f));
  const DepthImage zero(1, 1, 0.0f);
  FogSettings s;
  s.mode = FogMode::exp2;
  s.density = 1e-9f;
  s.color = glm::vec3(0.5f);
  EXPECT_EQ(run(scalar(), in, zero, cam, s).pixel(0, 0), in.pixel(0, 0));
  s.fog_skybox = true;
  EXPECT_EQ(run(scalar(), in, zero, cam, s).pixel(0, 0), glm::vec4(0.5f, 0.5f, 0.5f, 1.0f));
}

// 7. Orthographic cameras: depth is linear in eye depth in both conventions, and distance-based
// fog equals depth-based fog (parallel rays) — the case Godot ships broken.
TEST_P(Extreme, OrthographicVariant) {
  for (bool reversed : {false, true}) {
    OrthographicCamera oc;
    oc.ortho_size = 12.0f;
    oc.aspect = 2.0f;
    oc.near_plane = 0.5f;
    oc.far_plane = 300.0f;
    oc.reversed_z = reversed;
    const CameraParams cam = params_any_frame(oc);
    const TestFrame t = frame_for(cam, 40, 20, ColorFormat::rgba32f, 299.0, 0.1);
    for (const FogSettings& s : every_mode(FogMetric::depth, false)) {
      const Budgets b = check_against_double(scalar(), t, s);
      EXPECT_LE(b.factor, kFactorBudget) << to_string(s.mode);
      EXPECT_LE(b.color_rel, kColorRelBudget) << to_string(s.mode);
      FogSettings dist = s;
      dist.metric = FogMetric::distance;
      const ColorImage a = run(scalar(), t.color, t.depth, cam, s), c = run(scalar(), t.color, t.depth, cam, dist);
      EXPECT_EQ(std::memcmp(a.data(), c.data(), a.size_bytes()), 0) << "distance != depth, " << to_string(s.mode);
    }
    // Linear in raw depth: with linear fog from 0 to far, f = 1 - (eye - near) / far exactly
    // where eye = lerp(near, far, raw) (1 - raw with reversed Z).
    FogSettings lin;
    lin.mode = FogMode::linear;
    lin.start = 0.0f;
    lin.end = 300.0f;
    lin.color = glm::vec3(0.0f);
    lin.fog_skybox = true;
    DepthImage depth(5, 1);
    ColorImage white(5, 1);
    white = white_like(white);
    const float raws[5] = {0.0f, 0.25f, 0.5f, 0.75f, 1.0f};
    for (int x = 0; x < 5; ++x) depth.at(x, 0) = raws[x];
    const ColorImage out = run(scalar(), white, depth, cam, lin);
    for (int x = 0; x < 5; ++x) {
      const double r = reversed ? 1.0 - raws[x] : raws[x];
      const double eye = 0.5 + (300.0 - 0.5) * r;
      EXPECT_NEAR(out.pixel(x, 0).r, 1.0 - (eye - 0.5) / 300.0, 1e-6) << "raw " << raws[x];
    }
  }
}

// 9. A 120-degree FOV: distance-based = (depth-based + near) / cos(angle) at the corner pixel.
TEST_P(Extreme, WideFovDistanceIsDepthOverCosine) {
  PerspectiveCamera pc;
  pc.fov_y_deg = 120.0f;
  pc.aspect = 1.0f;
  const CameraParams cam = params_any_frame(pc);
  const int n = 33;
  const double eye = 250.0;
  const DepthImage depth(n, n, float(raw_from_eye(cam)(eye)));
  FogSettings s;
  s.mode = FogMode::linear;
  s.start = 0.0f;
  s.end = 4000.0f;
  s.color = glm::vec3(0.0f);
  ColorImage white(n, n);
  white = white_like(white);
  FogSettings dist = s;
  dist.metric = FogMetric::distance;
  const double dd = 4000.0 * (1.0 - run(scalar(), white, depth, cam, s).pixel(0, 0).r);
  const double dr = 4000.0 * (1.0 - run(scalar(), white, depth, cam, dist).pixel(0, 0).r);
  const double t = std::tan(60.0 * M_PI / 180.0);
  const double x = t * (2 * (0.5 / n) - 1), y = t * (2 * (1 - 0.5 / n) - 1);
  const double inv_cos = std::sqrt(x * x + y * y + 1);
  std::printf("[ worst    ] 120 deg corner: distance %.4f, (depth + near) / cos %.4f\n", dr, (dd + 0.3) * inv_cos);
  EXPECT_NEAR(dr, (dd + 0.3) * inv_cos, 2e-3 * inv_cos);
}

// 10. Sizes: 1x1, 1xN, Nx1 and sizes that are no multiple of any work-group or vector width.
TEST_P(Extreme, OddSizes) {
  for (auto [w, h] : {std::pair{1, 1}, std::pair{1, 37}, std::pair{37, 1}, std::pair{17, 3}, std::pair{33, 31}})
    for (ColorFormat format : {ColorFormat::rgba32f, ColorFormat::rgba16f}) {
      PerspectiveCamera pc;
      pc.aspect = float(w) / float(h);
      const CameraParams cam = params_any_frame(pc);
      const TestFrame t = frame_for(cam, w, h, format, 900.0);
      for (const FogSettings& s : every_mode(FogMetric::distance, false)) {
        const ColorImage out = run(scalar(), t.color, t.depth, cam, s);
        const ErrorStats e = compare_color(out, fog_scalar<double>(t.color, t.depth, cam, s), t.color, s.color);
        EXPECT_EQ(e.alpha_changed, 0u) << w << "x" << h;
        if (format == ColorFormat::rgba32f)
          EXPECT_LE(e.max_rel, kColorRelBudget) << w << "x" << h;
        else
          EXPECT_LE(e.max_half_ulps_beyond_factor, 1.0) << w << "x" << h;
      }
    }
}

INSTANTIATE_TEST_SUITE_P(KernelAndScalar, Extreme, ::testing::Values(false, true),
                         [](const auto& info) { return info.param ? "scalar" : "kernel"; });

// 10 (cont.). 8K: the kernel against the scalar float path (a float64 frame of 8K would need
// 1.6 GB; the float path is itself held to the double path above).
TEST(ExtremeSize, EightK) {
  FOGCL_REQUIRE_DEVICE();
  PerspectiveCamera pc;
  const CameraParams cam = params_any_frame(pc);
  const TestFrame t = frame_for(cam, 7680, 4320, ColorFormat::rgba16f, 900.0);
  FogSettings s;
  s.mode = FogMode::exp2;
  s.density = 0.003f;
  s.metric = FogMetric::distance;
  ColorImage k, c;
  shared_pass().apply(t.color, t.depth, k, cam, s);
  apply_fog_scalar(t.color, t.depth, c, cam, s);
  std::size_t differ = 0;
  double worst_ulps = 0;
  for (int y = 0; y < 4320; y += 1)
    for (int x = 0; x < 7680; ++x) {
      const glm::vec4 a = k.pixel(x, y), b = c.pixel(x, y);
      for (int ch = 0; ch < 4; ++ch) {
        const double ulps = std::fabs(double(a[ch]) - double(b[ch])) / half_ulp(b[ch]);
        if (ulps > 0) ++differ;
        worst_ulps = std::max(worst_ulps, ulps);
      }
    }
  std::printf("[ worst    ] 8K f16 kernel vs scalar float: %.2f half ulp, %zu channels differ\n", worst_ulps, differ);
  EXPECT_LE(worst_ulps, 1.0);
}

}  // namespace
}  // namespace fogcl::test
