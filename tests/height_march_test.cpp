// The height fog marched (docs/DESIGN.md §6.5): the segment formulas of kernels/fog_math.h
// (fog_height_march_segment, fog_height_march_out) on random settings and rays, in float (the
// kernel's polynomials) and double. Lit everywhere, the march over 1, 3, 8 or 64 segments equals
// §6.2's closed form (fog_height_pixel) within 1e-5; shadowed everywhere it equals the closed form
// with sun color 0; with one shadow edge on the ray its sun term is within the weight of the
// segment the edge crosses of the exact half-lit integral. Then the pass (VolumeSettings::height_fog):
// the kernel and the scalar march at full resolution against the deferred pass's closed form, lit
// and shadowed, and the kernel against the scalar march with shafts and volumes.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "fogcl/scalar.h"
#include "pass/formulas.h"
#include "volume/volume_formulas.h"
#include "volume_support.h"

namespace fogcl::test {
namespace {

using formulas::fog_height_length;
using formulas::fog_height_march_out;
using formulas::fog_height_march_segment;
using formulas::fog_height_pixel;
using formulas::fog_sun_lobe;

constexpr double kLitBudget = 1e-5;
constexpr int kSegmentCounts[] = {1, 3, 8, 64};

// One random height fog and ray, in the FOG_HP_* layout of §6.3.
struct Case {
  double p[FOG_HP_COUNT] = {};
  int features = 0;
  double s_hit = 0, wy = 0, d0 = 0, q_sun = 0, color[3] = {};
  int sky = 0;
  double far = 0;  // an infinite ray's finite stretch (the frame's farthest surface)
};

Case random_case(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Case c;
  c.features = FOG_HF_RGB | FOG_HF_SUN;
  const double k = u(rng) < 0.2 ? 0.0 : (u(rng) - 0.5) * 0.2;
  if (k != 0.0) c.features |= FOG_HF_FALLOFF;
  c.p[FOG_HP_K] = k;
  const bool same_in = u(rng) < 0.5;
  for (int ch = 0; ch < 3; ++ch) {
    c.p[FOG_HP_EXT + ch] = u(rng) < 0.1 ? 0.0 : 0.05 * u(rng);
    c.p[FOG_HP_IN + ch] = same_in ? c.p[FOG_HP_EXT + ch] : 0.05 * u(rng);
    c.p[FOG_HP_FOG + ch] = u(rng);
    c.p[FOG_HP_SUN + ch] = 2.0 * u(rng);
    c.color[ch] = 4.0 * u(rng);
  }
  if (same_in) c.features |= FOG_HF_SAME_IN;
  c.p[FOG_HP_START] = u(rng) < 0.5 ? 0.0 : 20.0 * u(rng);
  if (c.p[FOG_HP_START] > 0.0) c.features |= FOG_HF_START;
  c.p[FOG_HP_CUTOFF] = u(rng) < 0.5 ? INFINITY : c.p[FOG_HP_START] + 1.0 + 400.0 * u(rng);
  if (std::isfinite(c.p[FOG_HP_CUTOFF])) c.features |= FOG_HF_CUTOFF;
  c.p[FOG_HP_MAX] = 1.0;
  c.p[FOG_HP_MIN_T] = 0.0;
  c.p[FOG_HP_SUN_EXP] = 1.0 + 30.0 * u(rng);
  c.p[FOG_HP_SUN_START] = u(rng) < 0.5 ? 0.0 : 60.0 * u(rng);
  if (c.p[FOG_HP_SUN_START] > c.p[FOG_HP_START]) c.features |= FOG_HF_SUN_START;
  c.sky = u(rng) < 0.25;
  if (c.sky) c.features |= FOG_HF_SKYBOX;
  c.s_hit = c.sky ? 1000.0 : 1.0 + 500.0 * u(rng);
  c.far = 800.0;
  c.wy = 2.0 * u(rng) - 1.0;
  c.d0 = (u(rng) - 0.5) * 100.0;
  c.q_sun = 0.3 * u(rng);
  return c;
}

template <class T>
struct Params {
  T p[FOG_HP_COUNT];
  explicit Params(const Case& c) {
    for (int i = 0; i < FOG_HP_COUNT; ++i) p[i] = T(c.p[i]);
  }
};

// §6.2's closed form of the case in T, rgb out; returns whether the pixel is fogged.
template <class T>
int closed_form(const Case& c, const T* p, T rgb[3]) {
  for (int ch = 0; ch < 3; ++ch) rgb[ch] = T(c.color[ch]);
  return fog_height_pixel<T>(rgb, T(c.s_hit), c.sky, T(c.wy), T(c.d0), T(c.q_sun), p, c.features);
}

// The fog stretch [s0, s1] of §6.2 and whether it is an infinite ray.
template <class T>
void stretch(const Case& c, const T* p, T* s0, T* s1, int* infinite) {
  *s0 = (c.features & FOG_HF_START) ? p[FOG_HP_START] : T(0);
  *infinite = 0;
  if (c.sky) {
    if (c.features & FOG_HF_CUTOFF) *s1 = p[FOG_HP_CUTOFF];
    else *infinite = 1, *s1 = T(INFINITY);
  } else {
    *s1 = (c.features & FOG_HF_CUTOFF) ? std::fmin(T(c.s_hit), p[FOG_HP_CUTOFF]) : T(c.s_hit);
  }
}

// The march of §6.5 over n segments (an infinite ray: n - 1 to c.far, then the closed form's
// tail), visibility(σ) sampled at each segment's midpoint (the tail's start). Writes rgb; when
// weights is given, also each segment's sun term (double, the edge test's bound).
template <class T>
void march(const Case& c, const T* p, int n, const std::function<double(double)>& visibility, T rgb[3],
           std::vector<double>* edges = nullptr) {
  T s0, s1;
  int infinite;
  stretch(c, p, &s0, &s1, &infinite);
  const int falloff = (c.features & FOG_HF_FALLOFF) != 0;
  const T k = p[FOG_HP_K], wy = T(c.wy), d0 = T(c.d0);
  const T sun_from = (c.features & FOG_HF_SUN_START) ? std::fmax(s0, p[FOG_HP_SUN_START]) : s0;
  const T end = infinite ? std::fmax(T(c.far), s0) : s1;
  const int finite_segments = infinite ? n - 1 : n;
  T depth_ext[3] = {}, depth_in[3] = {}, depth_sun[3] = {}, ambient[3] = {}, sun[3] = {};
  for (int i = 0; i < n; ++i) {
    const T a = finite_segments == 0 ? s0 : s0 + (end - s0) * T(std::min(i, finite_segments)) / T(finite_segments);
    const bool tail = i == finite_segments;
    const T b = tail ? T(INFINITY) : (i + 1 == finite_segments ? end : s0 + (end - s0) * T(i + 1) / T(finite_segments));
    const T h = fog_height_length<T>(a, b, wy, d0, k, falloff, tail);
    const T a_sun = std::fmax(a, sun_from);
    const T h_sun = !(tail || b > a_sun) ? T(0)
                    : a_sun == a         ? h
                                         : fog_height_length<T>(a_sun, b, wy, d0, k, falloff, tail);
    const T v = T(visibility(tail ? double(a) : 0.5 * (double(a) + double(b))));
    for (int ch = 0; ch < 3; ++ch) {
      const T before = sun[ch];
      fog_height_march_segment<T>(h, h_sun, v, T(0), T(0), p, ch, (c.features & FOG_HF_SUN_START) != 0, &depth_ext[ch],
                                  &depth_in[ch], &depth_sun[ch], &ambient[ch], &sun[ch]);
      if (edges && ch == 0) edges->push_back(double(sun[ch] - before));
    }
  }
  const T lobe = fog_sun_lobe<T>(T(c.q_sun), p[FOG_HP_SUN_EXP]);
  for (int ch = 0; ch < 3; ++ch)
    rgb[ch] = fog_height_march_out<T>(T(c.color[ch]), depth_ext[ch], ambient[ch], sun[ch], lobe, p, ch, c.features);
}

template <class T>
double worst_lit_error(int cases, int n, bool shadowed) {
  std::mt19937 rng(1234 + n);
  double worst = 0.0;
  int fogged = 0;
  for (int t = 0; t < cases; ++t) {
    Case c = random_case(rng);
    Params<T> lit(c);
    T march_rgb[3], closed_rgb[3];
    march<T>(c, lit.p, n, [&](double) { return shadowed ? 0.0 : 1.0; }, march_rgb);
    if (shadowed)
      for (int ch = 0; ch < 3; ++ch) lit.p[FOG_HP_SUN + ch] = T(0);
    if (!closed_form<T>(c, lit.p, closed_rgb)) continue;
    ++fogged;
    for (int ch = 0; ch < 3; ++ch) {
      const double e = std::fabs(double(march_rgb[ch]) - double(closed_rgb[ch]));
      worst = std::isnan(e) ? INFINITY : std::max(worst, e);
    }
  }
  EXPECT_GT(fogged, cases / 2) << "too few fogged cases to check";
  return worst;
}

TEST(HeightMarch, LitEqualsTheClosedFormAtAnySegmentCount) {
  for (int n : kSegmentCounts) {
    const double f = worst_lit_error<float>(4000, n, false), d = worst_lit_error<double>(4000, n, false);
    std::printf("lit, %2d segments: worst |march - closed form| float %.3g, double %.3g\n", n, f, d);
    EXPECT_LE(f, kLitBudget) << n << " segments";
    EXPECT_LE(d, 1e-12) << n << " segments";
  }
}

TEST(HeightMarch, ShadowedRemovesExactlyTheSunTerm) {
  for (int n : kSegmentCounts) {
    const double f = worst_lit_error<float>(4000, n, true), d = worst_lit_error<double>(4000, n, true);
    std::printf("shadowed, %2d segments: worst |march - closed form without sun| float %.3g, double %.3g\n", n, f, d);
    EXPECT_LE(f, kLitBudget) << n << " segments";
    EXPECT_LE(d, 1e-12) << n << " segments";
  }
}

// One shadow edge at σ_e (lit before, shadowed after): the exact sun term is §6.2's over
// [s_sun', σ_e], S·λ·(1 - e^(-β_in H)); the march errs by at most the sun weight of the segment the
// edge crosses (§6.5's bound), and the error shrinks as the segments do.
TEST(HeightMarch, ShadowEdgeErrorWithinTheCrossedSegmentsWeight) {
  std::mt19937 rng(99);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  double worst_ratio = 0.0, worst_at[4] = {};
  int checked = 0;
  for (int t = 0; t < 2000; ++t) {
    Case c = random_case(rng);
    c.sky = 0;
    c.features &= ~FOG_HF_SKYBOX;
    c.features |= FOG_HF_SUN_START;  // the lit stretch's H computed apart
    Params<double> p(c);
    double s0, s1;
    int infinite;
    stretch(c, p.p, &s0, &s1, &infinite);
    const double sun_from = std::fmax(s0, p.p[FOG_HP_SUN_START]);
    if (!(s1 > sun_from + 1e-3)) continue;
    const double edge = sun_from + (s1 - sun_from) * u(rng);
    const int falloff = (c.features & FOG_HF_FALLOFF) != 0;
    const double h_lit = fog_height_length<double>(sun_from, edge, c.wy, c.d0, p.p[FOG_HP_K], falloff, 0);
    const double lobe = fog_sun_lobe<double>(c.q_sun, p.p[FOG_HP_SUN_EXP]);
    ++checked;
    for (int m = 0; m < 4; ++m) {
      const int n = kSegmentCounts[m];
      std::vector<double> weights;  // each segment's sun term when lit
      double rgb[3];
      march<double>(c, p.p, n, [](double) { return 1.0; }, rgb, &weights);
      march<double>(c, p.p, n, [&](double s) { return s < edge ? 1.0 : 0.0; }, rgb);
      // The marched sun term alone: rgb minus the same march fully shadowed.
      double dark[3];
      march<double>(c, p.p, n, [&](double) { return 0.0; }, dark);
      const double marched = rgb[0] - dark[0];
      const double exact = p.p[FOG_HP_SUN] * lobe * -std::expm1(-p.p[FOG_HP_IN] * h_lit);
      // The crossed segment: the one holding the edge (segments are even on [s0, s1]).
      const int crossed = std::min(n - 1, int(std::floor((edge - s0) / (s1 - s0) * n)));
      double bound = p.p[FOG_HP_SUN] * lobe * weights[crossed];
      for (int i = std::max(crossed - 1, 0); i <= std::min(crossed + 1, n - 1); ++i)
        bound = std::max(bound, p.p[FOG_HP_SUN] * lobe * weights[i]);
      const double err = std::fabs(marched - exact);
      worst_at[m] = std::max(worst_at[m], err);
      EXPECT_LE(err, bound + 1e-12) << "n " << n << " edge " << edge << " on [" << s0 << ", " << s1 << "]";
      if (bound > 1e-9) worst_ratio = std::max(worst_ratio, err / bound);
    }
  }
  std::printf("shadow edge (%d rays): worst sun-term error at 1/3/8/64 segments %.3g %.3g %.3g %.3g; "
              "worst error / crossed segment's weight %.3g\n",
              checked, worst_at[0], worst_at[1], worst_at[2], worst_at[3], worst_ratio);
  EXPECT_GT(checked, 500);
  EXPECT_LT(worst_at[3], worst_at[0]);
}


// A shadow map over every point the test rays reach (|x|, |z| < 1e3, |y| < 400; the camera's far
// plane is 200 away):
// filled with 1 everything is lit, with 0 everything is in shadow.
ShadowMap uniform_shadow_map(float fill) {
  ShadowMap m;
  glm::mat4& p = m.params.world_to_light_clip;
  p = glm::mat4(0.0f);
  p[0][0] = 1e-3f;
  p[2][1] = 1e-3f;
  p[1][2] = 1e-3f;  // light depth 0.5 + 1e-3 y: in (0.1, 0.9) for |y| < 400
  p[3][2] = 0.5f;
  p[3][3] = 1.0f;
  m.depth = DepthImage(8, 8, fill);
  return m;
}

// The demo frame without volumes, and a height fog of the variant's parts (falloff, per-channel
// in-scattering, start, cut-off, sun start, skybox) chosen by `seed`; seeds from kRgbSeeds on
// also give the extinction per channel (the target's coverage per channel).
constexpr int kRgbSeeds = 6, kSeeds = 8;
FogSettings marched_fog(const VolumeScene& scene, int seed) {
  FogSettings f;
  f.mode = FogMode::height;
  f.color = glm::vec3(0.6f, 0.7f, 0.8f);
  f.density = 0.06f;
  f.height.falloff = seed % 3 == 0 ? 0.0f : 0.35f;
  f.height.base_height = 0.5f;
  if (seed % 2) f.height.inscattering = glm::vec3(0.03f, 0.05f, 0.09f);
  f.height.start = seed % 4 >= 2 ? 1.5f : 0.0f;
  if (seed % 5 == 1) f.height.cutoff = 40.0f;
  f.fog_skybox = seed % 3 != 1;
  if (seed >= kRgbSeeds) f.height.extinction = glm::vec3(0.03f, 0.06f, 0.11f) * float(seed - kRgbSeeds + 1);
  SunLobe sun;
  sun.direction = scene.light.direction;
  sun.color = glm::vec3(1.5f, 1.2f, 0.9f);
  sun.exponent = 6.0f;
  sun.start = seed % 4 == 3 ? 4.0f : 0.0f;
  f.height.sun = sun;
  return f;
}

struct MarchedFrames {
  double kernel = 0, scalar = 0;  // worst |march - closed form| over RGB
  double sun = 0;                 // the largest sun term of the closed form (what a shadow removes)
};

// The test scene's light turned toward the camera's view, so that the lobe shows.
void face_the_light(VolumeTestScene& t) { t.scene.light.direction = glm::vec3(0.2f, 0.25f, 1.0f); }

// The march (kernel and scalar, full resolution, `steps`) with `shadow` against the deferred
// pass's closed form of `closed` (the same fog, or without its sun).
MarchedFrames march_against_closed_form(int seed, int steps, const ShadowMap* shadow, bool without_sun) {
  VolumeTestScene t = volume_test_scene(48, 30);
  t.scene.volumes.clear();
  face_the_light(t);
  VolumeSettings vs;
  vs.integrator = VolumeIntegrator::physical;
  vs.resolution_divisor = 1;
  vs.steps = steps;
  vs.height_fog = marched_fog(t.scene, seed);
  CameraParams posed = t.frame.params;
  posed.pose = t.scene.pose;
  FogSettings closed = *vs.height_fog;
  if (without_sun) closed.height.sun->color = glm::vec3(0.0f);
  FogSettings unlit = *vs.height_fog;
  unlit.height.sun->color = glm::vec3(0.0f);
  ColorImage want, want_lit, want_unlit, got_kernel, got_scalar;
  apply_fog_scalar(t.frame.color, t.frame.depth, want, posed, closed);
  apply_fog_scalar(t.frame.color, t.frame.depth, want_lit, posed, *vs.height_fog);
  apply_fog_scalar(t.frame.color, t.frame.depth, want_unlit, posed, unlit);
  static VolumePass pass(*runtime());
  pass.apply(t.frame.color, t.frame.depth, got_kernel, t.frame.params, t.scene, vs, shadow);
  apply_volumes_scalar(t.frame.color, t.frame.depth, got_scalar, t.frame.params, t.scene, vs, shadow);
  MarchedFrames r;
  for (int y = 0; y < want.height(); ++y)
    for (int x = 0; x < want.width(); ++x)
      for (int c = 0; c < 3; ++c) {
        const double w = want.pixel(x, y)[c];
        r.sun = std::max(r.sun, double(want_lit.pixel(x, y)[c]) - double(want_unlit.pixel(x, y)[c]));
        const double k = std::fabs(double(got_kernel.pixel(x, y)[c]) - w);
        const double sc = std::fabs(double(got_scalar.pixel(x, y)[c]) - w);
        r.kernel = std::isnan(k) ? INFINITY : std::max(r.kernel, k);
        r.scalar = std::isnan(sc) ? INFINITY : std::max(r.scalar, sc);
      }
  return r;
}

// §6.5's normative check on the pass: lit (no shadow map, or one lit everywhere) the composited
// march is the closed form within 1e-5 at every step count.
TEST(HeightMarchPass, LitEqualsTheDeferredClosedForm) {
  FOGCL_REQUIRE_DEVICE();
  const ShadowMap lit = uniform_shadow_map(1.0f);
  for (int steps : kSegmentCounts)
    for (int seed = 0; seed < kSeeds; ++seed)
      for (const ShadowMap* shadow : {static_cast<const ShadowMap*>(nullptr), &lit}) {
        const MarchedFrames r = march_against_closed_form(seed, steps, shadow, false);
        std::printf("lit%s, %2d steps, fog %d: worst |march - closed form| kernel %.3g, scalar %.3g (sun up to %.3g)\n",
                    shadow ? " map" : "", steps, seed, r.kernel, r.scalar, r.sun);
        EXPECT_GT(r.sun, 0.05) << "the lobe must show for the check to see it";
        EXPECT_LE(r.kernel, kLitBudget) << steps << " steps, fog " << seed;
        EXPECT_LE(r.scalar, kLitBudget) << steps << " steps, fog " << seed;
      }
}

// In shadow everywhere, the march is the closed form without its sun term.
TEST(HeightMarchPass, ShadowedEqualsTheClosedFormWithoutSun) {
  FOGCL_REQUIRE_DEVICE();
  const ShadowMap dark = uniform_shadow_map(0.0f);
  for (int steps : kSegmentCounts)
    for (int seed = 0; seed < kSeeds; ++seed) {
      const MarchedFrames r = march_against_closed_form(seed, steps, &dark, true);
      std::printf("shadowed, %2d steps, fog %d: worst |march - closed form without sun| kernel %.3g, scalar %.3g "
                  "(sun removed up to %.3g)\n", steps, seed, r.kernel, r.scalar, r.sun);
      EXPECT_GT(r.sun, 0.05) << "the lobe must show for the check to see it";
      EXPECT_LE(r.kernel, kLitBudget) << steps << " steps, fog " << seed;
      EXPECT_LE(r.scalar, kLitBudget) << steps << " steps, fog " << seed;
    }
}

// Shafts (the disc blocker's shadow map) through the fog with the test scene's volumes, at half
// resolution (per-channel extinction upsampled depth-aware and bilinear): the kernel against the
// scalar march, the noise sampled as the scalar path does on every device (a GPU's image filter
// has 8-bit weights: docs/accuracy.md#noise-sampling-on-gpus).
TEST(HeightMarchPass, KernelMatchesScalarWithShaftsAndVolumes) {
  FOGCL_REQUIRE_DEVICE();
  const ShadowMap shadow = synthetic_shadow_map(false);
  double worst = 0.0;
  for (int seed = 0; seed < kSeeds; ++seed) {
    VolumeTestScene t = volume_test_scene(48, 30);
    face_the_light(t);
    VolumeSettings vs;
    vs.integrator = VolumeIntegrator::physical;
    vs.steps = 24;
    vs.noise_sampling = NoiseSampling::buffer;
    vs.height_fog = marched_fog(t.scene, seed);
    // The per-channel coverage upsampled both ways (the other seeds: depth-aware).
    if (seed == kRgbSeeds + 1) vs.upsampling = VolumeUpsampling::bilinear;
    ColorImage got_kernel, got_scalar;
    static VolumePass pass(*runtime());
    pass.apply(t.frame.color, t.frame.depth, got_kernel, t.frame.params, t.scene, vs, &shadow);
    apply_volumes_scalar(t.frame.color, t.frame.depth, got_scalar, t.frame.params, t.scene, vs, &shadow);
    for (int y = 0; y < got_kernel.height(); ++y)
      for (int x = 0; x < got_kernel.width(); ++x)
        for (int c = 0; c < 3; ++c) {
          const double d = std::fabs(double(got_kernel.pixel(x, y)[c]) - double(got_scalar.pixel(x, y)[c]));
          worst = std::isnan(d) ? INFINITY : std::max(worst, d);
        }
  }
  std::printf("shafts and volumes: worst |kernel - scalar| %.3g\n", worst);
  EXPECT_LE(worst, 1e-5);
}

// The CPU lanes (16 target pixels per work-item) against the one-pixel kernel, at half and full
// resolution, jittered, with and without volumes and shafts, grey and per-channel extinction:
// the fog alone takes the same operations on every lane, so the bits agree; with volumes, PoCL's
// vector exp and expm1 of their segment weights may round apart (docs/volumetric.md §Lanes on
// CPU devices), within the kernel-vs-scalar budget.
TEST(HeightMarchPass, CpuLanesMatchTheOnePixelKernel) {
  FOGCL_REQUIRE_DEVICE();
  if (!runtime()->is_cpu()) GTEST_SKIP() << "the lanes are the CPU devices' march";
  static VolumePass lanes(*runtime());
  CpuCodegen one_pixel_codegen;
  one_pixel_codegen.one_pixel_per_work_item = true;
  static VolumePass one_pixel(*runtime(), nullptr, one_pixel_codegen);
  const ShadowMap shadow = synthetic_shadow_map(false);
  double worst_fog = 0.0, worst_volumes = 0.0, worst_lights = 0.0, brightest_lit = 0.0;
  std::size_t differing_fog = 0;
  // A point light by the camera and a spot over the ground volume (docs/volumetric.md#local-lights).
  LocalLight lamp;
  lamp.position = glm::vec3(1.0f, 1.2f, -2.0f);
  lamp.color = glm::vec3(1.0f, 0.8f, 0.6f);
  lamp.intensity = 5.0f;
  lamp.range = 8.0f;
  lamp.radius = 0.05f;
  LocalLight spot = lamp;
  spot.kind = LightKind::spot;
  spot.position = glm::vec3(-4.0f, 4.0f, 10.0f);
  spot.direction = glm::vec3(0.1f, -1.0f, 0.2f);
  spot.inner_angle = 10.0f;
  spot.outer_angle = 35.0f;
  spot.intensity = 40.0f;
  spot.range = 12.0f;
  for (int seed = 0; seed < kSeeds; ++seed)
    for (int what : {0, 1, 2}) {  // the fog alone, with volumes, with volumes (even seeds) and lights
      const bool volumes = what == 1 || (what == 2 && seed % 2 == 0), lights = what == 2;
      if (what == 1 && seed % 2) continue;  // fewer variants to build
      if (lights && seed > 4) continue;
      VolumeTestScene t = volume_test_scene(70, 30);  // a row of 35 target pixels: two full lane blocks and a tail
      face_the_light(t);
      if (!volumes) t.scene.volumes.clear();
      if (lights) t.scene.lights = {lamp, spot};
      VolumeSettings vs;
      vs.integrator = seed == 4 && !lights ? VolumeIntegrator::riemann : VolumeIntegrator::physical;
      vs.steps = 8 + 7 * seed;
      vs.resolution_divisor = seed % 2 ? 1 : 2;
      vs.height_fog = marched_fog(t.scene, seed);
      t.scene.frame_index = unsigned(seed);
      const ShadowMap* map = seed % 3 == 0 ? nullptr : &shadow;
      ColorImage got_lanes, got_one;
      lanes.apply(t.frame.color, t.frame.depth, got_lanes, t.frame.params, t.scene, vs, map);
      one_pixel.apply(t.frame.color, t.frame.depth, got_one, t.frame.params, t.scene, vs, map);
      EXPECT_NE(lanes.last_march_options().find("VOL_LANES=16"), std::string::npos) << lanes.last_march_options();
      EXPECT_EQ(one_pixel.last_march_options().find("VOL_LANES=16"), std::string::npos);
      for (int y = 0; y < got_lanes.height(); ++y)
        for (int x = 0; x < got_lanes.width(); ++x)
          for (int c = 0; c < 4; ++c) {
            const float a = got_lanes.pixel(x, y)[c], b = got_one.pixel(x, y)[c];
            const double d = std::fabs(double(a) - double(b));
            // with lights: relative to the value (lit fog is brighter than 1 near a lamp)
            double& worst = lights ? worst_lights : volumes ? worst_volumes : worst_fog;
            const double e = lights ? d / std::max(1.0, std::fabs(double(b))) : d;
            worst = std::isnan(d) ? INFINITY : std::max(worst, e);
            if (lights) brightest_lit = std::max(brightest_lit, double(b));
            if (!volumes && !lights && std::memcmp(&a, &b, sizeof a) != 0) ++differing_fog;
          }
    }
  std::printf("lanes vs one pixel: fog alone worst %.3g (%zu values differ in their bits), with volumes %.3g, "
              "with point and spot lights %.3g relative (brightest %.3g)\n",
              worst_fog, differing_fog, worst_volumes, worst_lights, brightest_lit);
  EXPECT_EQ(differing_fog, 0u);
  EXPECT_LE(worst_volumes, 1e-5);
  EXPECT_LE(worst_lights, 1e-5);
  EXPECT_GT(brightest_lit, 1.0);  // the lamps light the frame
}

// What the march cannot take is refused by name.
TEST(HeightMarchPass, RefusesWhatTheMarchCannotTake) {
  VolumeTestScene t = volume_test_scene(8, 6);
  VolumeSettings vs;
  vs.integrator = VolumeIntegrator::physical;
  vs.height_fog = marched_fog(t.scene, 0);
  const auto fails = [&](VolumeSettings s) {
    ColorImage out;
    return error_of([&] { apply_volumes_scalar(t.frame.color, t.frame.depth, out, t.frame.params, t.scene, s); });
  };
  VolumeSettings s = vs;
  s.integrator = VolumeIntegrator::stylized;
  EXPECT_MSG_HAS(fails(s), "physical integrator");
  s = vs;
  s.height_fog->height.max_opacity = 0.5f;
  EXPECT_MSG_HAS(fails(s), "maximum opacity must be 1");
  s = vs;
  s.height_fog->mode = FogMode::exp;
  EXPECT_MSG_HAS(fails(s), "mode must be height");
}


// Extinctions add (§6.5): a constant-density sphere inside the height fog, one ray through both
// to a surface, against a float64 quadrature of the combined medium (1e5 midpoints per piece
// between the sphere's boundaries): the march converges to it as the steps grow.
TEST(HeightMarch, VolumeInsideTheFogConvergesToTheCombinedMedium) {
  constexpr double kSigmaV = 0.4, kRadius = 4.0, kBeta = 0.05, kFalloff = 0.3, kBase = 0.0, kSurface = 30.0;
  constexpr double kAlbedo = 0.8, kAmbient = 0.3, kLight = 2.0, kFog = 0.5, kSun = 1.2, kExponent = 4.0;
  const glm::dvec3 origin(0.0, 1.0, 0.0), dir = glm::normalize(glm::dvec3(0.0, 0.1, 1.0)), center(0.0, 2.0, 12.0);
  const glm::dvec3 light = glm::normalize(glm::dvec3(0.1, 0.3, 1.0));
  std::array<float, VOL_F_COUNT> frame{};
  for (int k = 0; k < 3; ++k) {
    frame[std::size_t(VOL_F_LIGHT_DIR + k)] = float(light[k]);
    frame[std::size_t(VOL_F_LIGHT_COLOR + k)] = float(kLight);
    frame[std::size_t(VOL_F_HEIGHT_SUN + k)] = float(light[k]);
    frame[std::size_t(VOL_F_HEIGHT_P + FOG_HP_EXT + k)] = frame[std::size_t(VOL_F_HEIGHT_P + FOG_HP_IN + k)] = float(kBeta);
    frame[std::size_t(VOL_F_HEIGHT_P + FOG_HP_FOG + k)] = float(kFog);
    frame[std::size_t(VOL_F_HEIGHT_P + FOG_HP_SUN + k)] = float(kSun);
  }
  frame[VOL_F_HEIGHT_P + FOG_HP_K] = float(kFalloff);
  frame[VOL_F_HEIGHT_P + FOG_HP_CUTOFF] = INFINITY;
  frame[VOL_F_HEIGHT_P + FOG_HP_MAX] = 1.0f;
  frame[VOL_F_HEIGHT_P + FOG_HP_SUN_EXP] = float(kExponent);
  frame[VOL_F_HEIGHT_BASE] = float(kBase);
  std::array<float, VOL_V_STRIDE> vol{};
  for (int k = 0; k < 3; ++k) {
    vol[std::size_t(VOL_V_CENTER + k)] = float(center[k]);
    vol[std::size_t(VOL_V_ALBEDO + k)] = float(kAlbedo);
    vol[std::size_t(VOL_V_AMBIENT + k)] = float(kAmbient);
  }
  vol[VOL_V_RADIUS] = float(kRadius);
  vol[VOL_V_DENSITY] = float(kSigmaV);
  const int hf = FOG_HF_FALLOFF | FOG_HF_SUN | FOG_HF_SAME_IN;
  // The quadrature, from the same float inputs.
  const double phase = 1.0 / (4.0 * M_PI), lobe = std::pow(std::max(glm::dot(dir, light), 0.0), kExponent);
  const glm::dvec3 f = origin - center;
  const double b = glm::dot(f, dir), disc = b * b - (glm::dot(f, f) - kRadius * kRadius);
  ASSERT_GT(disc, 0.0);
  const double t0 = -b - std::sqrt(disc), t1 = -b + std::sqrt(disc);
  ASSERT_TRUE(t0 > 0.0 && t1 < kSurface);
  double in_r = 0.0, tau = 0.0;
  const double cuts[4] = {0.0, t0, t1, kSurface};
  for (int piece = 0; piece < 3; ++piece) {
    const int n = 100000;
    const double ds = (cuts[piece + 1] - cuts[piece]) / n;
    for (int i = 0; i < n; ++i) {
      const double s = cuts[piece] + (i + 0.5) * ds, h = origin.y + s * dir.y;
      const double sv = piece == 1 ? kSigmaV : 0.0, sf = kBeta * std::exp(-kFalloff * (h - kBase));
      const double sigma = sv + sf;
      const double source = sv * kAlbedo * (kLight * phase + kAmbient) + sf * (kFog + kSun * lobe);
      in_r += std::exp(-tau) * -std::expm1(-sigma * ds) / sigma * source;
      tau += sigma * ds;
    }
  }
  const double coverage = -std::expm1(-tau);
  double previous = INFINITY;
  for (int steps : {16, 128, 1024, 4096}) {
    double cover[3];
    const glm::dvec4 r = volume_formulas::vol_physical<double>(origin, dir, kSurface, 1.0, 0.5, vol.data(), 1,
                                                               frame.data(), nullptr, 0, nullptr, steps,
                                                               VOL_FEATURE_HEIGHT, hf, 0, cover);
    const double err = std::max(std::fabs(r.x - in_r), std::fabs(r.w - coverage));
    std::printf("sphere in the fog, %4d steps: |I - quadrature| %.3g, |A - quadrature| %.3g (I %.6f, A %.6f)\n",
                steps, std::fabs(r.x - in_r), std::fabs(r.w - coverage), in_r, coverage);
    EXPECT_LT(err, previous) << steps << " steps";
    previous = err;
  }
  EXPECT_LT(previous, 1e-5);
}

}  // namespace
}  // namespace fogcl::test
