// Height and atmospheric fog (FogMode::height, docs/DESIGN.md §6): the kernel against a float64
// evaluation of §6.2 for every part of the variant (falloff, per-channel coefficients, start,
// cut-off, maximum opacity, sun lobe, skybox) on every projection, Z direction, depth kind,
// storage and precision; the consistency case against the exp mode; the extreme cases of §6.3;
// Unreal's published form beside the closed form; the bit-exact rules; settings validation.
//
// Budget (§6.3): |color - ref| <= 4e-6 (1 + |c| + |F| + |S|) per channel, plus what float32 inputs
// force: the largest change of the exact (double) result when the pixel's distance, ω.y, the
// heights and 1 - cos(ω, ℓ) move by 4 float32 ulps (allowance(), computed per pixel).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "pass/formulas.h"
#include "settings/fog_coefficients.h"
#include "test_support.h"

namespace fogcl::test {
namespace {

constexpr double kBudget = 4e-6;
constexpr double kEps = 0x1p-24;  // half a float32 ulp at 1, relative

// A camera on a pose: `params` with the pose set.
CameraParams posed(CameraParams params, glm::vec3 eye, glm::vec3 forward, glm::vec3 up = {0, 1, 0}) {
  params.pose = CameraPose{eye, forward, up};
  return params;
}

// The float64 evaluation of one pixel (the same formulas as fog_scalar<double>), with the
// pixel's distance, ω.y, origin height and 1 - cos(ω, ℓ) scaled by (1 + a 4ε), (1 + b 4ε),
// (+ c 4ε |heights|), (1 + d 4ε).
struct PixelEval {
  double rgb[3];
  int fogged;
};
PixelEval eval_pixel(const ColorImage& in, const DepthImage& depth, const CameraParams& cam, const FogSettings& s,
                     const Variant& v, int x, int y, int a = 0, int b = 0, int c = 0, int d = 0) {
  using namespace formulas;
  const detail::HeightCoefficients<double> hc = detail::height_coefficients<double>(s, cam);
  const auto cn = fog_ray_corners(cam);
  const double u = fog_pixel_u(double(x), 1.0 / double(in.width())), vv = fog_pixel_v(double(y), double(in.height()));
  double ray[3];
  for (int k = 0; k < 3; ++k)
    ray[k] = fog_bilerp(double(cn[kBottomLeft][k]), double(cn[kBottomRight][k]), double(cn[kTopLeft][k]),
                        double(cn[kTopRight][k]), u, vv);
  const int features = v.height_features | (v.fog_skybox ? FOG_HF_SKYBOX : 0);
  int sky;
  double wy, d0, q;
  double s_hit = fog_height_geometry(double(depth.at(x, y)), ray[0], ray[1], ray[2], int(v.depth_kind), v.reversed_z,
                                     int(v.projection), double(cam.zbuffer_params.x), double(cam.zbuffer_params.y),
                                     double(cam.near_plane()), double(cam.far_plane()), hc.up[0], hc.up[1], hc.up[2],
                                     hc.light[0], hc.light[1], hc.light[2], (features & FOG_HF_SUN) != 0, hc.d0,
                                     &sky, &wy, &d0, &q);
  const double e4 = 4 * 2 * kEps;  // 4 float32 ulps
  const double heights = std::fabs(d0) + std::fabs(double(cam.pose->eye.y)) + (std::isfinite(s_hit) ? std::fabs(s_hit * wy) : 0);
  s_hit *= 1 + a * e4;
  wy *= 1 + b * e4;
  d0 += c * e4 * heights;
  q *= 1 + d * e4;
  const glm::vec4 p = in.pixel(x, y);
  PixelEval r{{p.x, p.y, p.z}, 0};
  r.fogged = fog_height_pixel(r.rgb, s_hit, sky, wy, d0, q, hc.p, features);
  return r;
}

// Per pixel: the reference and the allowance of the float32 inputs (max change over the 81
// perturbations), and the §6.3 budget scale 1 + |c| + |F| + |S|.
struct Check {
  double worst_excess = -1;  // max (|err| - allowance) / scale; <= kBudget passes
  double worst_err = 0, worst_allow = 0;
  std::size_t nonfinite = 0, pixels = 0;
  int wx = -1, wy = -1;
};

Check check_image(const ColorImage& got, const ColorImage& in, const DepthImage& depth, const CameraParams& cam,
                  const FogSettings& s, const Variant& v) {
  Check ch;
  const glm::vec3 sun = s.height.sun ? s.height.sun->color : glm::vec3(0.0f);
  for (int y = 0; y < in.height(); ++y)
    for (int x = 0; x < in.width(); ++x) {
      const PixelEval ref = eval_pixel(in, depth, cam, s, v, x, y);
      double allow[3] = {0, 0, 0};
      for (int a = -1; a <= 1; ++a)
        for (int b = -1; b <= 1; ++b)
          for (int c = -1; c <= 1; ++c)
            for (int d = -1; d <= 1; ++d) {
              if (!(a | b | c | d)) continue;
              const PixelEval e = eval_pixel(in, depth, cam, s, v, x, y, a, b, c, d);
              for (int k = 0; k < 3; ++k) allow[k] = std::max(allow[k], std::fabs(e.rgb[k] - ref.rgb[k]));
            }
      const glm::vec4 g = got.pixel(x, y), c = in.pixel(x, y);
      ++ch.pixels;
      for (int k = 0; k < 3; ++k) {
        if (!std::isfinite(g[k]) && std::isfinite(c[k])) ++ch.nonfinite;
        const double err = std::fabs(double(g[k]) - ref.rgb[k]);
        const double scale = 1 + std::fabs(c[k]) + std::fabs(s.color[k]) + std::fabs(sun[k]);
        const double excess = std::isnan(err) ? INFINITY : std::max(0.0, err - allow[k]) / scale;
        if (excess > ch.worst_excess) {
          ch.worst_excess = excess;
          ch.wx = x;
          ch.wy = y;
        }
        ch.worst_err = std::max(ch.worst_err, std::isnan(err) ? INFINITY : err / scale);
        ch.worst_allow = std::max(ch.worst_allow, allow[k] / scale);
      }
      if (g.w != c.w && !(std::isnan(g.w) && std::isnan(c.w))) ch.worst_excess = INFINITY;  // alpha untouched
    }
  return ch;
}

// A frame of random colors (0..4) over eye depths spread log-uniformly over [near, 2 far] (10 %
// sky), stored as `kind` (raw depth of the camera, or linear).
struct Frame {
  ColorImage color;
  DepthImage depth;
  CameraParams params;
};
Frame make_frame(int w, int h, const CameraParams& params, ColorFormat format, std::uint32_t seed) {
  Frame f{ColorImage(w, h, format), DepthImage(w, h), params};
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double n = std::max(params.near_plane(), 0.3f), far = std::isfinite(params.far_plane()) ? params.far_plane() : 5000.0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      f.color.set_pixel(x, y, glm::vec4(4 * unit(rng), 4 * unit(rng), 4 * unit(rng), unit(rng)));
      const bool sky = unit(rng) < 0.1;
      const double eye = n * std::pow(far / n, unit(rng));
      float value;
      if (params.depth_kind == DepthKind::eye) {
        value = sky ? INFINITY : float(eye);
      } else if (params.projection == Projection::perspective_infinite_far) {
        value = sky ? 0.0f : float(n / eye);
      } else if (params.projection == Projection::orthographic) {
        const double raw = (eye - params.near_plane()) / (far - params.near_plane());
        value = sky ? (params.reversed_z ? 0.0f : 1.0f) : float(params.reversed_z ? 1 - raw : raw);
      } else {
        const double zx = params.zbuffer_params.x, zy = params.zbuffer_params.y;
        value = sky ? (params.reversed_z ? 0.0f : 1.0f) : float((far / eye - zy) / zx);
      }
      f.depth.at(x, y) = value;
    }
  return f;
}

CameraParams perspective(bool reversed = false, bool infinite = false, float far = 1000.0f) {
  PerspectiveCamera c;
  c.aspect = 1.5f;
  c.far_plane = far;
  c.reversed_z = reversed || infinite;
  c.infinite_far = infinite;
  CameraParams p = make_camera_params(c);
  p.non_square_pixels = true;  // one camera for the tests' frames of every size
  return p;
}

CameraParams orthographic(bool reversed = false) {
  OrthographicCamera c;
  c.aspect = 1.5f;
  c.ortho_size = 40.0f;
  c.reversed_z = reversed;
  CameraParams p = make_camera_params(c);
  p.non_square_pixels = true;  // one camera for the tests' frames of every size
  return p;
}

FogSettings base_height_settings() {
  FogSettings s;
  s.mode = FogMode::height;
  s.color = glm::vec3(0.55f, 0.6f, 0.7f);
  s.density = 0.004f;
  return s;
}

// The parts a case turns on.
enum Parts : int {
  kFalloff = 1, kRgb = 2, kStart = 4, kCutoff = 8, kMaxOpacity = 16, kSun = 32, kSunStart = 64, kSkybox = 128,
  kRgbSameIn = 256,  // per-channel extinction, in-scattering left to default to it
};
FogSettings settings_with(int parts) {
  FogSettings s = base_height_settings();
  HeightFogSettings& h = s.height;
  if (parts & kFalloff) {
    h.falloff = 0.03f;
    h.base_height = 5.0f;
  }
  if (parts & kRgb) {
    h.extinction = glm::vec3(0.002f, 0.004f, 0.009f);
    h.inscattering = glm::vec3(0.001f, 0.003f, 0.0f);  // a zero channel
  }
  if (parts & kRgbSameIn) h.extinction = glm::vec3(0.002f, 0.004f, 0.009f);
  if (parts & kStart) h.start = 30.0f;
  if (parts & kCutoff) h.cutoff = 600.0f;
  if (parts & kMaxOpacity) h.max_opacity = 0.8f;
  if (parts & (kSun | kSunStart)) {
    SunLobe sun;
    sun.direction = glm::vec3(0.3f, 0.25f, 1.0f);
    sun.color = glm::vec3(2.0f, 1.6f, 1.0f);
    sun.exponent = 16.0f;
    if (parts & kSunStart) sun.start = 80.0f;
    h.sun = sun;
  }
  s.fog_skybox = (parts & kSkybox) != 0;
  return s;
}

struct VariantCase {
  const char* name;
  int parts;
  CameraParams (*camera)();
  ColorFormat format;
  Precision precision;
};

CameraParams cam_persp() { return perspective(); }
CameraParams cam_rev() { return perspective(true); }
CameraParams cam_inf() { return perspective(true, true); }
CameraParams cam_ortho() { return orthographic(); }
CameraParams cam_ortho_rev() { return orthographic(true); }
CameraParams cam_eye() {
  CameraParams p = perspective();
  p.depth_kind = DepthKind::eye;
  return p;
}

const VariantCase kCases[] = {
    {"grey, nothing else", 0, cam_persp, ColorFormat::rgba32f, Precision::precise},
    {"falloff", kFalloff, cam_persp, ColorFormat::rgba32f, Precision::precise},
    {"falloff rgb", kFalloff | kRgb, cam_persp, ColorFormat::rgba32f, Precision::precise},
    {"falloff start cutoff", kFalloff | kStart | kCutoff, cam_rev, ColorFormat::rgba32f, Precision::precise},
    {"falloff max-opacity skybox", kFalloff | kMaxOpacity | kSkybox, cam_persp, ColorFormat::rgba32f,
     Precision::precise},
    {"rgb sun skybox", kRgb | kSun | kSkybox, cam_persp, ColorFormat::rgba32f, Precision::precise},
    {"all", kFalloff | kRgb | kStart | kCutoff | kMaxOpacity | kSun | kSunStart | kSkybox, cam_persp,
     ColorFormat::rgba32f, Precision::precise},
    {"falloff sun sun-start skybox, infinite far", kFalloff | kSun | kSunStart | kSkybox, cam_inf,
     ColorFormat::rgba32f, Precision::precise},
    {"falloff rgb skybox, orthographic", kFalloff | kRgb | kSkybox, cam_ortho, ColorFormat::rgba32f,
     Precision::precise},
    {"falloff start, orthographic reversed", kFalloff | kStart, cam_ortho_rev, ColorFormat::rgba32f,
     Precision::precise},
    {"falloff rgb skybox, eye depth", kFalloff | kRgb | kSkybox, cam_eye, ColorFormat::rgba32f, Precision::precise},
    {"falloff rgb sun skybox, rgba16f", kFalloff | kRgb | kSun | kSkybox, cam_persp, ColorFormat::rgba16f,
     Precision::precise},
    {"falloff rgb same-in sun skybox", kFalloff | kRgbSameIn | kSun | kSkybox, cam_persp, ColorFormat::rgba32f,
     Precision::precise},
    {"falloff rgb sun skybox, fast", kFalloff | kRgb | kSun | kSkybox, cam_persp, ColorFormat::rgba32f,
     Precision::fast},
};

class HeightKernelVsReference : public ::testing::TestWithParam<int> {};

TEST_P(HeightKernelVsReference, WithinBudget) {
  FOGCL_REQUIRE_DEVICE();
  const VariantCase& c = kCases[GetParam()];
  FogSettings s = settings_with(c.parts);
  s.precision = c.precision;
  // Looking a little down from 12 above the base, turned and rolled: every component of the
  // rotation is used.
  const CameraParams cam = posed(c.camera(), {3.0f, 12.0f, -7.0f}, {0.4f, -0.08f, 1.0f}, {0.05f, 1.0f, 0.0f});
  const Frame f = make_frame(47, 31, cam, c.format, 1234u + unsigned(GetParam()));
  ColorImage scalar_out;
  apply_fog_scalar(f.color, f.depth, scalar_out, cam, s);
  const Variant v = select_variant(s, cam, c.format);
  ASSERT_EQ(v.mode, KernelMode::height);
  // The library's double path is these formulas: the same bits.
  const FogResult<double> ref = fog_scalar<double>(f.color, f.depth, cam, s);
  for (int y = 0; y < f.color.height(); y += 5)
    for (int x = 0; x < f.color.width(); x += 3) {
      const PixelEval e = eval_pixel(f.color, f.depth, cam, s, v, x, y);
      for (int k = 0; k < 3; ++k)
        ASSERT_EQ(e.rgb[k], ref.rgba[4 * (std::size_t(y) * f.color.width() + x) + k]) << x << "," << y;
    }
  // Half storage: the output's own rounding on top (one half ulp of the reference).
  const auto half_ulps = [&](const ColorImage& img) {
    Check h;
    for (int y = 0; y < img.height(); ++y)
      for (int x = 0; x < img.width(); ++x)
        for (int k = 0; k < 3; ++k) {
          const double r = ref.rgba[4 * (std::size_t(y) * img.width() + x) + k];
          const double err = std::fabs(double(img.pixel(x, y)[k]) - r);
          h.worst_err = std::max(h.worst_err, std::isnan(err) ? INFINITY : err / half_ulp(r));
        }
    h.worst_excess = h.worst_err;
    return h;
  };
  const Check sc = c.format == ColorFormat::rgba16f ? half_ulps(scalar_out)
                                                    : check_image(scalar_out, f.color, f.depth, cam, s, v);
  for (const KernelPath& path : kernel_paths()) {
    FogPass& pass = *path.pass;
    ColorImage out;
    pass.apply(f.color, f.depth, out, cam, s);
    ASSERT_EQ(pass.last_variant(), v);
    // PoCL's CPU blocks run the same operations as scalar<float> (fma where written, IEEE
    // selects): the same bits, whichever of its 16-lane blocks or one-pixel row tails a pixel is
    // in. The GPUs' one-pixel kernel takes the device's exp (fog_math.h, FOG_DEVICE_EXP): budgets.
    std::size_t differing = 0;
    for (std::size_t b = 0; b < out.size_bytes(); b += 4)
      differing += std::memcmp(static_cast<const char*>(out.data()) + b, static_cast<const char*>(scalar_out.data()) + b, 4) != 0;
    const bool same_bits_expected = path.is_cpu_blocks && c.precision == Precision::precise;
    if (same_bits_expected) {
      EXPECT_EQ(differing, 0u) << "kernel vs scalar<float> bits";
    }
    const Check kc = c.format == ColorFormat::rgba16f ? half_ulps(out)  // in half ulps of the reference
                                                      : check_image(out, f.color, f.depth, cam, s, v);
    std::printf("[ worst    ] %-44s %-9s %-60s kernel: err %.2e excess %.2e (allow %.1e) | scalar<float>: err %.2e excess %.2e | %zu floats differ\n",
                c.name, path.name, describe(v).c_str(), kc.worst_err, kc.worst_excess, kc.worst_allow, sc.worst_err,
                sc.worst_excess, differing);
    EXPECT_EQ(kc.nonfinite, 0u);
    EXPECT_EQ(sc.nonfinite, 0u);
    // fast: -cl-fast-relaxed-math's built-ins have no ulp bound in the spec; measured, held to 4e-5.
    const double budget = c.format == ColorFormat::rgba16f ? 1.0 : c.precision == Precision::fast ? 4e-5 : kBudget;
    EXPECT_LE(kc.worst_excess, budget) << path.name << " at " << kc.wx << "," << kc.wy;
    EXPECT_LE(sc.worst_excess, c.format == ColorFormat::rgba16f ? 1.0 : kBudget) << "at " << sc.wx << "," << sc.wy;
  }
}

INSTANTIATE_TEST_SUITE_P(Variants, HeightKernelVsReference,
                         ::testing::Range(0, int(sizeof kCases / sizeof kCases[0])));

// CPU devices: the 16-lane blocks (and one-pixel row tails) with the target's SIMD builtins and
// the portable OpenCL C path give scalar<float>'s bits, in both storages; pass-through pixels (sky,
// in front of the start) keep theirs, signalling NaNs included.
TEST(HeightFog, CpuBlocksPortableAndTargetMatchScalarBitForBit) {
  FOGCL_REQUIRE_DEVICE();
  if (!runtime()->is_cpu()) GTEST_SKIP() << "not a CPU device";
  CpuCodegen plain;
  plain.target_intrinsics = false;
  FogPass portable_pass(*runtime(), plain);
  for (const ColorFormat format : {ColorFormat::rgba32f, ColorFormat::rgba16f}) {
    FogSettings s = settings_with(kFalloff | kRgb | kStart | kSun | kSunStart);
    const CameraParams cam = posed(perspective(), {0.0f, 4.0f, 0.0f}, {0.1f, -0.05f, 1.0f});
    Frame f = make_frame(67, 9, cam, format, 99);
    // Signalling NaNs in the sky (passed through) and in front of the start.
    for (int x = 0; x < 67; x += 5) {
      f.depth.at(x, 2) = 1.0f;
      f.depth.at(x, 3) = float((cam.far_plane() / 2.0 - cam.zbuffer_params.y) / cam.zbuffer_params.x);  // eye 2
    }
    if (format == ColorFormat::rgba32f)
      for (int x = 0; x < 67; x += 5)
        for (int y : {2, 3}) {
          const std::uint32_t snan = 0x7fa00001u;
          std::memcpy(f.color.rgba32f() + 4 * (std::size_t(y) * 67 + x), &snan, 4);
        }
    else
      for (int x = 0; x < 67; x += 5)
        for (int y : {2, 3}) f.color.rgba16f()[4 * (std::size_t(y) * 67 + x)] = 0x7d01;  // half sNaN
    ColorImage target, portable, scalar;
    shared_pass().apply(f.color, f.depth, target, cam, s);
    portable_pass.apply(f.color, f.depth, portable, cam, s);
    apply_fog_scalar(f.color, f.depth, scalar, cam, s);
    std::size_t dt = 0, dp = 0, kept = 0;
    const std::size_t bpp = bytes_per_pixel(format);
    const auto* in = static_cast<const unsigned char*>(f.color.data());
    for (std::size_t i = 0; i < f.depth.pixel_count(); ++i) {
      dt += std::memcmp(static_cast<const unsigned char*>(target.data()) + i * bpp,
                        static_cast<const unsigned char*>(scalar.data()) + i * bpp, bpp) != 0;
      dp += std::memcmp(static_cast<const unsigned char*>(portable.data()) + i * bpp,
                        static_cast<const unsigned char*>(scalar.data()) + i * bpp, bpp) != 0;
      kept += std::memcmp(static_cast<const unsigned char*>(target.data()) + i * bpp, in + i * bpp, bpp) == 0;
    }
    std::printf("[ bits     ] %s: target %zu, portable %zu pixels differ from scalar<float>; %zu of %zu passed through\n",
                to_string(format), dt, dp, kept, f.depth.pixel_count());
    EXPECT_EQ(dt, 0u);
    EXPECT_EQ(dp, 0u);
    for (int x = 0; x < 67; x += 5)
      for (int y : {2, 3})
        EXPECT_EQ(std::memcmp(static_cast<const unsigned char*>(target.data()) + (std::size_t(y) * 67 + x) * bpp,
                              in + (std::size_t(y) * 67 + x) * bpp, bpp),
                  0)
            << to_string(format) << " pixel " << x << "," << y << " must pass through bit for bit";
  }
}

// The integration API: the caller's context, queue and buffers; the same bits as apply(); an
// enqueue without the pose is refused before anything is enqueued.
TEST(HeightFog, IntegrationApiTakesThePoseAndMatchesApply) {
  FOGCL_REQUIRE_DEVICE();
  Runtime& rt = *runtime();
  const cl::Context ctx = wrap(rt.context());
  const cl::CommandQueue queue = wrap(rt.queue());
  const CameraParams cam = posed(perspective(), {1.0f, 6.0f, -3.0f}, {0.2f, -0.1f, 1.0f});
  Frame f = make_frame(37, 21, cam, ColorFormat::rgba32f, 5);
  const FogSettings s = settings_with(kFalloff | kRgb | kSun | kSkybox);
  cl::Buffer color_in(ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, f.color.size_bytes(), f.color.data());
  cl::Buffer depth(ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, f.depth.size_bytes(), f.depth.data());
  cl::Buffer color_out(ctx, CL_MEM_READ_WRITE, f.color.size_bytes());
  FrameBuffers fb;
  fb.width = 37;
  fb.height = 21;
  fb.color_in = color_in();
  fb.depth = depth();
  fb.color_out = color_out();
  FogPass pass(rt.context(), rt.device());
  pass.prepare(s, cam, ColorFormat::rgba32f);
  CameraParams no_pose = cam;
  no_pose.pose.reset();
  EXPECT_MSG_HAS(error_of([&] { pass.enqueue(rt.queue(), fb, no_pose, s); }), "camera pose");
  const cl::Event done = adopt(pass.enqueue(rt.queue(), fb, cam, s));
  ColorImage got(37, 21);
  queue.enqueueReadBuffer(color_out, CL_TRUE, 0, got.size_bytes(), got.data(), nullptr);
  ColorImage want;
  shared_pass().apply(f.color, f.depth, want, cam, s);
  EXPECT_EQ(std::memcmp(got.data(), want.data(), got.size_bytes()), 0);
}

// The float paths' exp, expm1 (x <= 0) and log1p (-1 < y <= 0) polynomials against the C
// library in double, in ulps of the float result, on a sweep of their ranges (log1p's correction
// y / (u - 1) adds two roundings to its log: 3 ulps).
TEST(HeightFog, PolynomialsWithinTheirUlps) {
  const auto ulps = [](float got, double want) {
    if (want == 0) return got == 0 ? 0.0 : INFINITY;
    const double ulp = std::ldexp(1.0, std::ilogb(float(want)) - 23);
    return std::fabs(double(got) - want) / std::max(ulp, 0x1p-149);
  };
  double exp_worst = 0, expm1_worst = 0, log1p_worst = 0;
  float exp_at = 0, expm1_at = 0, log1p_at = 0;
  for (float x = -87.0f; x <= 88.0f; x = std::nextafter(x + 1e-2f * std::fabs(x) + 1e-5f, INFINITY)) {
    const double e = ulps(formulas::fog_exp_poly(x), std::exp(double(x)));
    if (e > exp_worst) exp_worst = e, exp_at = x;
  }
  for (float x = -1e-30f; x >= -40.0f; x *= 1.001f) {
    const double e = ulps(formulas::fog_expm1_neg_poly(x), std::expm1(double(x)));
    if (e > expm1_worst) expm1_worst = e, expm1_at = x;
    float em;
    const float t = formulas::fog_exp_expm1_neg_poly(x, &em);
    EXPECT_EQ(em, formulas::fog_expm1_neg_poly(x)) << x;
    if (x > -87.0f) {
      EXPECT_LE(ulps(t, std::exp(double(x))), 2.0) << x;
    }
  }
  for (float y = -1e-30f; y > -1.0f; y = std::min(y * 1.001f, std::nextafter(y, -1.0f))) {
    if (y <= -0.999999f) break;
    const double e = ulps(formulas::fog_log1p_neg_poly(y), std::log1p(double(y)));
    if (e > log1p_worst) log1p_worst = e, log1p_at = y;
  }
  std::printf("[ ulps     ] exp %.2f (at %g), expm1 %.2f (at %g), log1p %.2f (at %g)\n", exp_worst, exp_at,
              expm1_worst, expm1_at, log1p_worst, log1p_at);
  EXPECT_LE(exp_worst, 2.0);
  EXPECT_LE(expm1_worst, 2.0);
  EXPECT_LE(log1p_worst, 3.5);
}

// The variant holds only what the scene uses.
TEST(HeightVariant, BuildOptionsOnlyForWhatIsUsed) {
  const CameraParams cam = posed(perspective(), {0, 2, 0}, {0, 0, 1});
  const std::string plain = build_options(select_variant(settings_with(0), cam, ColorFormat::rgba32f));
  std::printf("[ options  ] %s\n", plain.c_str());
  EXPECT_NE(plain.find("-D FOG_MODE=5"), std::string::npos);
  // Grey, in-scattering = extinction: one exponential gives T and J; nothing else.
  EXPECT_EQ(plain.find("FOG_HEIGHT_"), plain.find("FOG_HEIGHT_SAME_IN"));
  EXPECT_EQ(plain.find("FOG_HEIGHT_", plain.find("FOG_HEIGHT_SAME_IN") + 1), std::string::npos);
  EXPECT_EQ(plain.find("FOG_SKYBOX"), std::string::npos);
  EXPECT_NE(plain.find("FOG_VECTOR_WIDTH=1"), std::string::npos);
  const std::string all = build_options(select_variant(settings_with(255), cam, ColorFormat::rgba16f));
  std::printf("[ options  ] %s\n", all.c_str());
  for (const char* o : {"FOG_HEIGHT_FALLOFF", "FOG_HEIGHT_RGB", "FOG_HEIGHT_START", "FOG_HEIGHT_CUTOFF",
                        "FOG_HEIGHT_MAX_OPACITY", "FOG_HEIGHT_SUN ", "FOG_HEIGHT_SUN_START", "FOG_SKYBOX",
                        "FOG_COLOR_HALF"})
    EXPECT_NE((all + " ").find(o), std::string::npos) << o;
  // No pass at all: maximum opacity 0, or no coefficients.
  FogSettings s = settings_with(kFalloff);
  s.height.max_opacity = 0.0f;
  EXPECT_FALSE(select_variant(s, cam, ColorFormat::rgba32f).needs_pass());
  s = settings_with(kFalloff | kSun);
  s.density = 0.0f;
  EXPECT_FALSE(select_variant(s, cam, ColorFormat::rgba32f).needs_pass());
  // A sun of color 0 is no lobe.
  s = settings_with(kSun);
  s.height.sun->color = glm::vec3(0.0f);
  EXPECT_EQ(select_variant(s, cam, ColorFormat::rgba32f).height_features & kHeightSun, 0);
}

// k = 0, grey, no start, cut-off or sun: §2's exp mode on the distance-based metric.
TEST(HeightFog, ConsistentWithExpModeAlongTheRay) {
  FOGCL_REQUIRE_DEVICE();
  const CameraParams cam = posed(perspective(), {0, 2, 0}, {0.2f, 0.1f, 1.0f});
  const Frame f = make_frame(64, 40, cam, ColorFormat::rgba32f, 7);
  FogSettings h = base_height_settings();
  h.density = 0.006f;
  FogSettings e = h;
  e.mode = FogMode::exp;
  e.metric = FogMetric::distance;
  ColorImage ho, eo;
  shared_pass().apply(f.color, f.depth, ho, cam, h);
  shared_pass().apply(f.color, f.depth, eo, cam, e);
  const FogResult<double> eref = fog_scalar<double>(f.color, f.depth, cam, e);
  double worst = 0, worst_ref = 0;
  for (int y = 0; y < 40; ++y)
    for (int x = 0; x < 64; ++x)
      for (int k = 0; k < 3; ++k) {
        const double c = f.color.pixel(x, y)[k], scale = 1 + std::fabs(c) + std::fabs(h.color[k]);
        worst = std::max(worst, std::fabs(double(ho.pixel(x, y)[k]) - double(eo.pixel(x, y)[k])) / scale);
        worst_ref = std::max(worst_ref, std::fabs(double(ho.pixel(x, y)[k]) - eref.rgba[4 * (y * 64 + x) + k]) / scale);
      }
  std::printf("[ worst    ] height (k = 0) vs exp distance-based: kernel vs kernel %.2e, height kernel vs exp float64 %.2e\n",
              worst, worst_ref);
  EXPECT_LE(worst, 2 * kBudget);
  EXPECT_LE(worst_ref, kBudget);
}

// §6.3's extreme cases, each on a small frame whose middle row and column are exactly horizontal
// (a level camera) or exactly along forward. Every pixel sees one surface distance.
struct Extreme {
  const char* name;
  glm::vec3 eye, forward;
  float distance;  // eye depth of every pixel (+inf: sky)
  float falloff, base, density;
  float start = 0;
  bool skybox = false;
  glm::vec3 extinction{-1.0f};  // -1: density
};

ColorImage probe_color(int w, int h, ColorFormat format, float value) {
  ColorImage c(w, h, format);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) c.set_pixel(x, y, glm::vec4(value, 2 * value + 0.25f, 3.0f, 0.5f));
  return c;
}

const Extreme kExtremes[] = {
    {"camera at +1e5, level", {0, 1e5f, 0}, {0, 0, 1}, 500, 0.01f, 0, 0.01f},
    {"camera at -1e5, level", {0, -1e5f, 0}, {0, 0, 1}, 500, 0.01f, 0, 0.01f},
    {"camera at +1e5 looking down 1e5", {0, 1e5f, 0}, {0, -1, 0.01f}, 1e5f, 0.001f, 0, 0.01f},
    {"2 km below a dense layer, looking up", {0, -2000, 0}, {0, 1, 0.01f}, 5000, 0.02f, 0, 0.05f},
    {"2 km below a dense layer, looking down", {0, -2000, 0}, {0, -1, 0.01f}, 5000, 0.02f, 0, 0.05f},
    {"2 km above a dense layer, looking down", {0, 2000, 0}, {0, -1, 0.01f}, 5000, 0.02f, 0, 0.05f},
    {"2 km above a dense layer, looking up", {0, 2000, 0}, {0, 1, 0.01f}, 5000, 0.02f, 0, 0.05f},
    {"|k dh| = 1e4, looking down", {0, 0, 0}, {0, -1, 0.001f}, 1e4f, 1.0f, 0, 0.01f},
    {"|k dh| = 1e4, looking up", {0, 0, 0}, {0, 1, 0.001f}, 1e4f, 1.0f, 0, 0.01f},
    {"k dh = 0 exactly (k = 0)", {0, 50, 0}, {0.3f, -0.2f, 1}, 300, 0.0f, 0, 0.01f},
    {"rays exactly horizontal, k = 1", {0, 3, 0}, {0, 0, 1}, 1000, 1.0f, 0, 0.002f},
    {"rays within 1e-7 of horizontal", {0, 3, 0}, {0, 1e-7f, 1}, 1000, 0.5f, 0, 0.002f},
    {"distances to 1e7", {0, 10, 0}, {0, 0.001f, 1}, 1e7f, 0.0001f, 0, 1e-5f},
    {"distances to 1e7, steep", {0, 10, 0}, {0, -0.3f, 1}, 1e7f, 1e-5f, 0, 1e-6f},
    {"start beyond the surface", {0, 3, 0}, {0.1f, -0.1f, 1}, 50, 0.05f, 0, 0.01f, 100.0f},
    {"sky looking up (finite), skybox fogged", {0, 3, 0}, {0, 1, 0.2f}, INFINITY, 0.05f, 0, 0.02f, 0, true},
    {"sky looking down (infinite), skybox fogged", {0, 3, 0}, {0, -1, 0.2f}, INFINITY, 0.05f, 0, 0.02f, 0, true},
    {"zero channel, infinite ray", {0, 3, 0}, {0, -1, 0.2f}, INFINITY, 0.05f, 0, 0.02f, 0, true,
     {0.0f, 0.01f, 0.0f}},
};

TEST(HeightFog, ExtremeCasesWithinBudget) {
  FOGCL_REQUIRE_DEVICE();
  const int w = 9, h = 7;
  for (const Extreme& e : kExtremes) {
    PerspectiveCamera pc;
    pc.aspect = float(w) / float(h);
    pc.near_plane = 0.3f;
    pc.far_plane = 2e7f;
    pc.reversed_z = true;
    pc.infinite_far = true;  // distances to 1e7 from a near plane of 0.3
    CameraParams cam = make_camera_params(pc);
    cam.depth_kind = DepthKind::eye;
    cam = posed(cam, e.eye, e.forward);
    FogSettings s = base_height_settings();
    s.density = e.density;
    s.height.falloff = e.falloff;
    s.height.base_height = e.base;
    s.height.start = e.start;
    s.fog_skybox = e.skybox;
    if (e.extinction.x >= 0) s.height.extinction = e.extinction;
    DepthImage depth(w, h);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) depth.at(x, y) = e.distance;
    double worst = 0, worst_allow = 0;
    std::size_t nonfinite = 0;
    const Variant v = select_variant(s, cam, ColorFormat::rgba32f);
    for (const float value : {0.0f, 1.0f, 100.0f}) {
      const ColorImage color = probe_color(w, h, ColorFormat::rgba32f, value);
      ColorImage scalar_out;
      apply_fog_scalar(color, depth, scalar_out, cam, s);
      const Check sc = check_image(scalar_out, color, depth, cam, s, v);
      worst = std::max(worst, sc.worst_excess);
      nonfinite += sc.nonfinite;
      for (const KernelPath& path : kernel_paths()) {
        ColorImage out;
        path.pass->apply(color, depth, out, cam, s);
        const Check c = check_image(out, color, depth, cam, s, path.pass->last_variant());
        worst = std::max(worst, c.worst_excess);
        worst_allow = std::max(worst_allow, c.worst_allow);
        nonfinite += c.nonfinite;
      }
    }
    std::printf("[ extreme  ] %-46s excess over allowance %.2e (allowance up to %.1e)\n", e.name, worst, worst_allow);
    EXPECT_EQ(nonfinite, 0u) << e.name;
    EXPECT_LE(worst, kBudget) << e.name;
  }
}

// §6.2 with k = 0: the fogged sky is an infinite ray too (H = +inf), never its far-plane distance,
// which a start or a sun start may pass. Where beta > 0, T = 0 and J = 1: the sky is exactly F,
// plus S λ with a lobe; a channel with in-scattering 0 and extinction > 0 is exactly 0, one with
// both 0 keeps its color. 96 x 55 pixels looking up, every other pixel sky, the rest surfaces
// (within the budget of the float64 path, finite), on every path.
TEST(HeightFog, ZeroFalloffSkyIsInfinitelyFar) {
  struct Case {
    const char* name;
    float density, start = 0;
    glm::vec3 fog{0.5f};
    glm::vec3 extinction{-1.0f}, inscattering{-1.0f};  // -1: unset
    float sun_start = -1;                               // -1: no lobe
    bool reversed = false, sky_infinite = false;
    Precision precision = Precision::precise;
    ColorFormat format = ColorFormat::rgba32f;
  };
  const Case cases[] = {
      {"density 0.004", 0.004f},
      {"density 0.004, a zero fog channel, per-channel extinction", 0.0f, 0, {0.5f, 0.0f, 0.25f}, {0.004f, 0.002f, 0.006f}},
      {"in-scattering 0 in G, no coefficient in B", 0.0f, 0, {0.5f, 0.25f, 0.75f}, {0.004f, 0.003f, 0.0f},
       {0.004f, 0.0f, 0.0f}},
      {"density 0.5, start 2000 (past the far plane)", 0.5f, 2000},
      {"start 2000, sky infinite", 0.5f, 2000, glm::vec3(0.5f), glm::vec3(-1.0f), glm::vec3(-1.0f), -1, false, true},
      {"start 2000, reversed Z", 0.5f, 2000, glm::vec3(0.5f), glm::vec3(-1.0f), glm::vec3(-1.0f), -1, true},
      {"start 2000, fast", 0.5f, 2000, glm::vec3(0.5f), glm::vec3(-1.0f), glm::vec3(-1.0f), -1, false, false,
       Precision::fast},
      {"start 2000, half", 0.5f, 2000, glm::vec3(0.5f), glm::vec3(-1.0f), glm::vec3(-1.0f), -1, false, false,
       Precision::precise, ColorFormat::rgba16f},
      {"start 2000, sun start 1e38", 0.5f, 2000, glm::vec3(0.5f), glm::vec3(-1.0f), glm::vec3(-1.0f), 1e38f},
      {"sun start 2000, reversed Z, half, fast", 0.5f, 0, glm::vec3(0.5f), glm::vec3(-1.0f), glm::vec3(-1.0f), 2000, true,
       false, Precision::fast, ColorFormat::rgba16f},
  };
  const int w = 96, h = 55;
  double worst_sky = 0, worst_surface = 0;
  std::size_t sky_pixels = 0, nonfinite = 0, sky_wrong = 0;
  for (const Case& c : cases) {
    const CameraParams cam = posed(perspective(c.reversed), {0, 2, 0}, {0.1f, 1.0f, 0.3f});
    Frame f = make_frame(w, h, cam, c.format, 55u);
    for (int y = 0; y < h; ++y)
      for (int x = (y & 1); x < w; x += 2) f.depth.at(x, y) = c.reversed ? 0.0f : 1.0f;
    FogSettings s = base_height_settings();
    s.density = c.density;
    s.color = c.fog;
    s.fog_skybox = true;
    s.sky = c.sky_infinite ? SkyDistance::infinite : SkyDistance::far_plane;
    s.precision = c.precision;
    s.height.start = c.start;
    if (c.extinction.x >= 0) s.height.extinction = c.extinction;
    if (c.inscattering.x >= 0) s.height.inscattering = c.inscattering;
    if (c.sun_start >= 0) {
      SunLobe sun;
      sun.direction = glm::vec3(0.2f, 1.0f, 0.4f);
      sun.color = glm::vec3(1.0f);
      sun.start = c.sun_start;
      s.height.sun = sun;
    }
    const Variant v = select_variant(s, cam, c.format);
    ASSERT_EQ(v.height_features & kHeightFalloff, 0) << c.name;
    const FogResult<double> ref = fog_scalar<double>(f.color, f.depth, cam, s);
    std::vector<std::pair<const char*, ColorImage>> outs;
    outs.emplace_back("scalar", ColorImage());
    apply_fog_scalar(f.color, f.depth, outs.back().second, cam, s);
    if (runtime() != nullptr)
      for (const KernelPath& path : kernel_paths()) {
        outs.emplace_back(path.name, ColorImage());
        path.pass->apply(f.color, f.depth, outs.back().second, cam, s);
      }
    const glm::vec3 ext = c.extinction.x >= 0 ? c.extinction : glm::vec3(c.density);
    const glm::vec3 in = c.inscattering.x >= 0 ? c.inscattering : ext;
    double case_sky = 0, case_surface = 0;
    for (const auto& [path, out] : outs)
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
          const bool sky = ((x + y) & 1) == 0;
          sky_pixels += sky;
          const glm::vec4 got = out.pixel(x, y), color = f.color.pixel(x, y);
          for (int k = 0; k < 3; ++k) {
            const double r = ref.rgba[4 * (std::size_t(y) * w + x) + k];
            const double err = std::fabs(double(got[k]) - r);
            const double scale = 1 + std::fabs(color[k]) + std::fabs(c.fog[k]) + (c.sun_start >= 0 ? 1 : 0);
            nonfinite += !std::isfinite(got[k]);
            const double allow = c.format == ColorFormat::rgba16f ? half_ulp(r) / scale : 0.0;
            if (sky) {
              // The float64 path's sky: F J + S λ J_sun with J = J_sun = 1 (0 without in-scattering),
              // or the color where the channel has no coefficient.
              const double want = ext[k] == 0 && in[k] == 0 ? color[k] : in[k] == 0 ? 0.0 : c.fog[k];
              if (c.sun_start < 0 && (r != want || got[k] != float(want)) && ++sky_wrong <= 5)
                ADD_FAILURE() << c.name << " " << path << " at " << x << "," << y << " channel " << k << ": " << got[k]
                              << " (float64 path " << r << "), not " << want;
              case_sky = std::max(case_sky, std::isnan(err) ? INFINITY : err / scale - allow);
            } else {
              case_surface = std::max(case_surface, std::isnan(err) ? INFINITY : err / scale - allow);
            }
          }
        }
    std::printf("[ k = 0 sky] %-58s sky err %.2e, surfaces err %.2e (of 1 + |c| + |F| + |S|, beyond half's rounding)\n",
                c.name, case_sky, case_surface);
    // The lobe: S λ from the float32 ω and λ's polynomials, within §6.3's budget (fast: 4e-5).
    const double budget = c.precision == Precision::fast ? 4e-5 : kBudget;
    EXPECT_LE(case_sky, budget) << c.name;
    EXPECT_LE(case_surface, budget) << c.name;
    worst_sky = std::max(worst_sky, case_sky);
    worst_surface = std::max(worst_surface, case_surface);
  }
  std::printf("[ worst    ] k = 0, fogged sky: %zu sky pixels, %zu sky channels not exactly F (or 0, or c), worst sky "
              "err %.2e, surfaces %.2e, %zu non-finite\n",
              sky_pixels, sky_wrong, worst_sky, worst_surface, nonfinite);
  EXPECT_EQ(sky_wrong, 0u);
  EXPECT_EQ(nonfinite, 0u);
}

// Unreal's published line integral (HeightFogCommon.ush, CalculateLineIntegralShared): the
// falloff times the height change taken from heights, (1 - e^-x) / x, and its first-order Taylor
// series below |x| = 0.01, exponentiated at the ray's origin; beside fogcl's closed form, both
// in float against double, relative error of H.
TEST(HeightFog, UnrealFormBesideTheClosedForm) {
  struct Point {
    const char* name;
    double h0, wy, L, k;
  };
  const Point points[] = {
      {"horizontal (x = 0)", 3, 0.0, 1000, 0.5},
      {"x = 1e-7", 3, 1e-7, 1000, 1e-3},
      {"x = 1e-4", 3, 1e-4, 1000, 1e-3},
      {"x = 0.009 (Taylor)", 3, 0.009, 100, 0.01},
      {"x = 0.011 (closed)", 3, 0.011, 100, 0.01},
      {"x = 1", 3, 0.1, 100, 0.1},
      {"x = 0.0099 (Taylor)", 3, 0.0099, 100, 0.01},
      {"x = 0.02 (closed)", 3, 0.02, 100, 0.01},
      {"camera at 1e5, x = 1e-3", 1e5, 1e-3, 100, 1e-5},
      {"camera at 1e5, level", 1e5, 0.0, 1000, 1e-5},
      {"x = -100, looking down (e^100)", 400, -1.0, 1000, 0.1},
      {"x = -1e4, looking down into thin air", 1e4, -1.0, 1e4, 1.0},
  };
  std::printf("[ unreal   ] %-36s %12s %12s\n", "point", "closed form", "Unreal");
  double worst_closed = 0;
  for (const Point& p : points) {
    const double h1 = p.h0 + p.wy * p.L;
    const double x = p.k * p.wy * p.L;
    const double exact = p.L * std::exp(-p.k * (x >= 0 ? p.h0 : h1)) * (x == 0 ? 1.0 : -std::expm1(-std::fabs(x)) / std::fabs(x));
    const float closed = formulas::fog_height_length<float>(0.0f, float(p.L), float(p.wy), float(p.h0), float(p.k), 1, 0);
    // Unreal's: x from the heights, the origin's exponential.
    const float fh0 = float(p.h0), fh1 = fh0 + float(p.wy) * float(p.L);
    const float fx = float(p.k) * (fh1 - fh0);
    const float g = std::fabs(fx) > 0.01f ? (1.0f - std::exp(-fx)) / fx : 1.0f - 0.5f * fx;
    const float unreal = float(p.L) * std::exp(-float(p.k) * fh0) * g;
    const auto rel = [&](double v) { return exact == 0 ? std::fabs(v) : std::fabs(v - exact) / exact; };
    std::printf("[ unreal   ] %-36s %12.3e %12.3e\n", p.name, rel(closed), rel(unreal));
    if (std::isfinite(exact)) worst_closed = std::max(worst_closed, rel(closed));
  }
  // The closed form loses no digits but those of its float inputs and exp (the exponent at 1e5
  // magnifies the input's rounding: |k h| ulps): measured 1.45e-7 at worst (x = 0.0099).
  std::printf("[ worst    ] closed form %.3e\n", worst_closed);
  EXPECT_LE(worst_closed, 1e-6);
}

// §6.2's bit-exact rules.
TEST(HeightFog, BitExactRules) {
  FOGCL_REQUIRE_DEVICE();
  const int w = 5, h = 3;
  const CameraParams cam = posed(perspective(), {0, 3, 0}, {0, -0.2f, 1});
  ColorImage color(w, h, ColorFormat::rgba32f);
  DepthImage depth(w, h);
  const float nan = std::nanf("1");
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      color.set_pixel(x, y, glm::vec4(x == 0 ? nan : -0.0f, INFINITY, 1.25f, nan));
      depth.at(x, y) = 0.999f;
    }
  for (const KernelPath& path : kernel_paths()) {
    FogPass& pass = *path.pass;
    // H = 0: the start is beyond every surface.
    FogSettings s = base_height_settings();
    s.height.start = 1e6f;
    s.height.cutoff = 2e6f;
    ColorImage out;
    pass.apply(color, depth, out, cam, s);
    EXPECT_EQ(std::memcmp(out.data(), color.data(), color.size_bytes()), 0) << path.name << ": H = 0 must pass bit for bit";
    // m = 0: no pass at all.
    s = base_height_settings();
    s.height.max_opacity = 0.0f;
    pass.apply(color, depth, out, cam, s);
    EXPECT_FALSE(pass.last_variant().needs_pass());
    EXPECT_EQ(std::memcmp(out.data(), color.data(), color.size_bytes()), 0) << path.name << ": m = 0 must pass bit for bit";
    // T = 0: a NaN or Inf color never leaks; the output is exactly F J.
    s = base_height_settings();
    s.density = 1e3f;
    pass.apply(color, depth, out, cam, s);
    ColorImage scalar_out;
    apply_fog_scalar(color, depth, scalar_out, cam, s);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        for (int k = 0; k < 3; ++k) {
          EXPECT_EQ(out.pixel(x, y)[k], s.color[k]) << path.name << " " << x << "," << y << " channel " << k;
          EXPECT_EQ(scalar_out.pixel(x, y)[k], s.color[k]) << x << "," << y << " channel " << k;
        }
  }
}

TEST(HeightSettings, ValidationNamesTheValueAndTheRule) {
  const CameraParams cam = posed(perspective(), {0, 2, 0}, {0, 0, 1});
  const auto msg = [&](FogSettings s, const CameraParams& c) {
    return error_of([&] { (void)select_variant(s, c, ColorFormat::rgba32f); });
  };
  FogSettings s = base_height_settings();
  EXPECT_MSG_HAS(msg(s, perspective()), "camera pose");
  s.height.extinction = glm::vec3(0.1f, -1.0f, 0.0f);
  EXPECT_MSG_HAS(msg(s, cam), "extinction must be finite and >= 0");
  s = base_height_settings();
  s.height.falloff = NAN;
  EXPECT_MSG_HAS(msg(s, cam), "falloff must be finite");
  s = base_height_settings();
  s.height.base_height = INFINITY;
  EXPECT_MSG_HAS(msg(s, cam), "base height must be finite");
  s = base_height_settings();
  s.height.max_opacity = 1.5f;
  EXPECT_MSG_HAS(msg(s, cam), "maximum opacity must be in [0, 1] (got 1.5)");
  s = base_height_settings();
  s.height.start = 10.0f;
  s.height.cutoff = 10.0f;
  EXPECT_MSG_HAS(msg(s, cam), "cut-off must be > start");
  s = settings_with(kSun);
  s.height.sun->exponent = 0.0f;
  EXPECT_MSG_HAS(msg(s, cam), "sun exponent must be finite and > 0");
  s = base_height_settings();
  EXPECT_MSG_HAS(msg(s, posed(perspective(), {0, 2, 0}, {0, 1, 0}, {0, 1, 0})), "parallel");
}

}  // namespace
}  // namespace fogcl::test
