// Linear depth as a kernel input (kernels/fog_math.h, fog_view_distance_linear): eye depth and
// radial distance reach the formulas as they are, so the fog factor keeps the deferred pass's
// 2e-7 budget against the float64 evaluation for every near plane from 1e-6 up, on the kernel
// (CPU block path and row tails) and the scalar float path. Raw depth made from the same values
// is measured beside it, to show what the linear variants avoid.
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

#include "fogcl/depth_kinds.h"
#include "test_support.h"
#include "volume_support.h"

namespace fogcl::test {
namespace {

constexpr double kLinearFactorBudget = 2e-7;
constexpr float kFar = 1000.0f;

CameraParams camera_params(float near_plane, bool reversed, DepthKind kind) {
  PerspectiveCamera c;
  c.fov_y_deg = 60.0f;
  c.aspect = 16.0f / 9.0f;
  c.near_plane = near_plane;
  c.far_plane = kFar;
  c.reversed_z = reversed;
  CameraParams p = make_camera_params(c);
  p.depth_kind = kind;
  p.non_square_pixels = true;  // one camera for the tests' frames of every size
  return p;
}

// A frame of linear depth: eye depths log-uniform in [0.5, 900] (an offline render's range;
// radial distance: the same eye depths along each pixel's ray), and a first row of background
// and out-of-range values.
DepthImage linear_frame(int w, int h, DepthKind kind, const CameraParams& unit_params) {
  DepthImage d(w, h);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> log_depth(std::log(0.5), std::log(900.0));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) d.at(x, y) = float(std::exp(log_depth(rng)));
  const float specials[] = {std::numeric_limits<float>::infinity(), std::numeric_limits<float>::quiet_NaN(), 0.0f,
                            -3.0f, 1e10f, 1e-7f, 999.95f /* sky by the 0.9999 far rule */, 1200.0f};
  for (int i = 0; i < int(std::size(specials)) && i < w; ++i) d.at(i, 0) = specials[i];
  if (kind == DepthKind::distance) {
    // eye -> radial distance with the same geometry the library uses (exact enough: the
    // reference reads the value as given).
    DepthImage ones(w, h, 1.0f);
    CameraParams p = unit_params;
    p.depth_kind = DepthKind::raw;
    // to_eye_depth(1) gives 1 / |ray1|: the pixel's ray length at view z = 1 is its inverse.
    to_eye_depth(ones, DepthKind::distance, p);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) d.at(x, y) = float(double(d.at(x, y)) / double(ones.at(x, y)));
  }
  return d;
}

struct Case {
  FogMode mode;
  float a, b;  // linear start, end; exp / exp2 density
};

FogSettings settings_for(const Case& c, FogMetric metric, bool skybox, SkyDistance sky) {
  FogSettings s;
  s.mode = c.mode;
  s.color = glm::vec3(0.0f);  // a probe run: white in, the output is f (factor_error)
  s.start = c.a;
  s.end = c.b;
  s.density = c.a;
  s.metric = metric;
  s.fog_skybox = skybox;
  s.sky = sky;
  return s;
}

// Factor errors of the kernel and the scalar float path against fog_scalar<double>.
struct Errors {
  double kernel = 0, scalar = 0;
};
Errors factor_errors(const DepthImage& depth, const CameraParams& p, const FogSettings& s) {
  const ColorImage white = white_like(ColorImage(depth.width(), depth.height(), ColorFormat::rgba32f));
  const FogResult<double> ref = fog_scalar<double>(white, depth, p, s);
  ColorImage kernel_out, scalar_out;
  shared_pass().apply(white, depth, kernel_out, p, s);
  apply_fog_scalar(white, depth, scalar_out, p, s);
  return {factor_error(kernel_out, ref), factor_error(scalar_out, ref)};
}

TEST(LinearDepth, FactorWithinBudgetForEveryNearPlane) {
  FOGCL_REQUIRE_DEVICE();
  const int w = 53, h = 29;  // three 16-pixel blocks and a 5-pixel tail per row
  const Case cases[] = {{FogMode::linear, 0.0f, 1000.0f}, {FogMode::exp, 0.003f, 0}, {FogMode::exp2, 0.002f, 0}};
  double worst_tiny_near_raw_route = 0;
  for (float near_plane : {1e-6f, 1e-4f, 1e-2f, 0.3f, 10.0f})
    for (DepthKind kind : {DepthKind::eye, DepthKind::distance}) {
      double worst = 0, worst_raw_route = 0;
      const DepthImage depth = linear_frame(w, h, kind, camera_params(near_plane, false, DepthKind::raw));
      // Linear depth reads no Z direction: conventional Z here (reversed in SkyAtInfinity), the
      // skybox test on for distance-based fog only, so that each program is built once.
      const CameraParams p = camera_params(near_plane, false, kind);
      for (const Case& c : cases)
        for (FogMetric metric : {FogMetric::depth, FogMetric::distance}) {
          const bool skybox = metric == FogMetric::distance;
          const FogSettings s = settings_for(c, metric, skybox, SkyDistance::far_plane);
          const Errors e = factor_errors(depth, p, s);
          EXPECT_EQ(shared_pass().last_variant().depth_kind, kind);
          EXPECT_LE(e.kernel, kLinearFactorBudget) << "near " << near_plane << " " << to_string(kind) << " "
                                                   << to_string(c.mode) << " " << to_string(metric);
          EXPECT_LE(e.scalar, kLinearFactorBudget) << "near " << near_plane << " " << to_string(kind);
          worst = std::max({worst, e.kernel, e.scalar});
          // The route linear depth took before: through float raw depth (to_raw_depth), measured
          // against the same exact reference.
          DepthImage raw = depth;
          CameraParams raw_params = p;
          raw_params.depth_kind = DepthKind::raw;
          to_raw_depth(raw, kind, raw_params);
          const ColorImage white = white_like(ColorImage(w, h, ColorFormat::rgba32f));
          ColorImage via_raw;
          apply_fog_scalar(white, raw, via_raw, raw_params, s);
          worst_raw_route = std::max(worst_raw_route, factor_error(via_raw, fog_scalar<double>(white, depth, p, s)));
        }
      std::printf("[ worst    ] near %-7g %-8s linear kernel/scalar f %.2e (budget %.0e) | through raw depth %.2e\n",
                  double(near_plane), to_string(kind), worst, kLinearFactorBudget, worst_raw_route);
      if (near_plane == 1e-6f) worst_tiny_near_raw_route = std::max(worst_tiny_near_raw_route, worst_raw_route);
    }
  // At near 1e-6 float raw depth has no digit of these depths left: that route was wrong outright.
  EXPECT_GT(worst_tiny_near_raw_route, 0.1);
}

TEST(LinearDepth, SkyAndBackgroundFollowTheRawRules) {
  FOGCL_REQUIRE_DEVICE();
  // Sky: +inf, NaN, <= 0, from 0.9999 far on. Sky test on: those pixels stay unfogged (f = 1);
  // sky at infinity: fully fogged (f = 0); nearer than near is the near plane (d = 0 depth-based).
  const CameraParams p = camera_params(0.3f, false, DepthKind::eye);
  DepthImage d(8, 1);
  const float values[] = {std::numeric_limits<float>::infinity(), std::numeric_limits<float>::quiet_NaN(), 0.0f,
                          -1.0f, 999.95f, 0.1f, 500.0f, 999.8f};
  for (int x = 0; x < 8; ++x) d.at(x, 0) = values[x];
  const ColorImage white = white_like(ColorImage(8, 1, ColorFormat::rgba32f));
  for (SkyDistance sky : {SkyDistance::far_plane, SkyDistance::infinite}) {
    FogSettings s = settings_for({FogMode::linear, 0.0f, 2000.0f}, FogMetric::depth, false, sky);
    ColorImage out;
    shared_pass().apply(white, d, out, p, s);
    for (int x = 0; x < 5; ++x)
      EXPECT_EQ(out.pixel(x, 0).r, sky == SkyDistance::infinite ? 0.0f : 1.0f) << "value " << values[x];
    EXPECT_EQ(out.pixel(5, 0).r, 1.0f);  // 0.1 < near: the near plane, d = 0, f = 1
    EXPECT_NEAR(out.pixel(6, 0).r, (2000.0 - 499.7) / 2000.0, 1e-7);
    EXPECT_NEAR(out.pixel(7, 0).r, (2000.0 - 999.5) / 2000.0, 1e-7);  // below 0.9999 far: a surface
  }
}

TEST(LinearDepth, SkyAtInfinityFogsTheSkyInEveryMode) {
  FOGCL_REQUIRE_DEVICE();
  for (DepthKind kind : {DepthKind::raw, DepthKind::eye}) {
    const CameraParams p = camera_params(0.3f, true, kind);
    DepthImage d(2, 1);
    d.at(0, 0) = kind == DepthKind::raw ? 0.0f : std::numeric_limits<float>::infinity();  // sky
    d.at(1, 0) = kind == DepthKind::raw ? float(raw_from_eye_depth(50.0, p)) : 50.0f;
    const ColorImage white = white_like(ColorImage(2, 1, ColorFormat::rgba32f));
    for (const Case& c : {Case{FogMode::linear, 0.0f, 5000.0f}, Case{FogMode::linear, 100.0f, 100.0f},
                          Case{FogMode::exp, 1e-4f, 0}, Case{FogMode::exp2, 1e-4f, 0}}) {
      const FogSettings s = settings_for(c, FogMetric::distance, false, SkyDistance::infinite);
      ColorImage kernel_out, scalar_out;
      shared_pass().apply(white, d, kernel_out, p, s);
      apply_fog_scalar(white, d, scalar_out, p, s);
      EXPECT_TRUE(shared_pass().last_variant().sky_infinite);
      EXPECT_EQ(kernel_out.pixel(0, 0).r, 0.0f) << to_string(c.mode) << " " << to_string(kind);
      EXPECT_EQ(scalar_out.pixel(0, 0).r, 0.0f) << to_string(c.mode);
      EXPECT_GT(kernel_out.pixel(1, 0).r, 0.0f) << to_string(c.mode);  // a surface keeps its own fog
    }
  }
}

TEST(LinearDepth, VariantsAreBuiltOnlyWhenAsked) {
  FogSettings s;
  s.mode = FogMode::exp;
  CameraParams p = camera_params(0.3f, false, DepthKind::raw);
  const DeviceTraits cpu;
  std::string o = build_options(select_variant(s, p, ColorFormat::rgba32f), cpu);
  EXPECT_EQ(o.find("FOG_DEPTH_KIND"), std::string::npos) << o;
  EXPECT_EQ(o.find("FOG_SKY_INFINITE"), std::string::npos) << o;
  p.depth_kind = DepthKind::distance;
  s.sky = SkyDistance::infinite;
  const Variant v = select_variant(s, p, ColorFormat::rgba32f);
  EXPECT_TRUE(v.fog_skybox);  // sky at infinity implies fogging it
  o = build_options(v, cpu);
  EXPECT_NE(o.find("-D FOG_DEPTH_KIND=2"), std::string::npos) << o;
  EXPECT_NE(o.find("-D FOG_SKY_INFINITE"), std::string::npos) << o;
}

TEST(LinearDepth, RadialDistanceNeedsRaysThatMeet) {
  OrthographicCamera c;
  CameraParams p = make_camera_params(c);
  p.depth_kind = DepthKind::distance;
  EXPECT_MSG_HAS(error_of([&] { validate(p); }), "radial distance depth needs a perspective camera");
}


// The volume pass reads eye depth as it is too (vol_eye_depth, vol_inverse_eye_depth): the demo
// scene's depth as eye depth, at near 0.3 and at near 1e-6 (where float raw depth holds nothing),
// kernel against the double reference on the same eye depths, both integrators, full and half
// resolution (the depth-aware composite reads the frame's depth).
TEST(LinearDepth, VolumePassReadsEyeDepth) {
  FOGCL_REQUIRE_DEVICE();
  static VolumePass pass(*runtime());
  for (float near_plane : {0.3f, 1e-6f})
    for (VolumeIntegrator integrator : {VolumeIntegrator::stylized, VolumeIntegrator::physical})
      for (int divisor : {1, 2}) {
        VolumeTestScene t = volume_test_scene(64, 36);
        DepthImage eye = t.frame.depth;  // raw -> eye depth in double (LinearEyeDepth), sky -> +inf
        for (int y = 0; y < eye.height(); ++y)
          for (int x = 0; x < eye.width(); ++x) {
            const float raw = eye.at(x, y);
            eye.at(x, y) = raw == 1.0f ? std::numeric_limits<float>::infinity()
                                       : float(1.0 / (double(t.frame.params.zbuffer_params.z) * raw +
                                                      double(t.frame.params.zbuffer_params.w)));
          }
        PerspectiveCamera cam = t.frame.camera;
        cam.near_plane = near_plane;
        CameraParams p = make_camera_params(cam);
        p.depth_kind = DepthKind::eye;
        VolumeSettings settings;
        settings.integrator = integrator;
        settings.resolution_divisor = divisor;
        settings.steps = 32;
        ColorImage out;
        pass.apply(t.frame.color, eye, out, p, t.scene, settings);
        const VolumeResult<double> ref = volumes_scalar<double>(t.frame.color, eye, p, t.scene, settings);
        const VolumeErrorStats s = compare_volumes(out, ref, 2e-4);
        std::printf("[ worst    ] volumes on eye depth, near %g %s 1/%d: %s\n", double(near_plane),
                    to_string(integrator), divisor, describe(s).c_str());
        EXPECT_GT(s.fogged, s.pixels / 10);
        EXPECT_EQ(s.nonfinite, 0u);
        EXPECT_LE(s.over, s.pixels / 1000) << describe(s);
      }
}
}  // namespace
}  // namespace fogcl::test
