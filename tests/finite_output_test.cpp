// Finite input gives finite output in every mode (docs/DESIGN.md §2: "Finite inputs never produce
// a non-finite output"; §6.2 for height fog), as a property: random settings over each flag's
// whole documented range (docs/cli.md; validate(FogSettings)) -- densities, coefficients and the
// falloff up to FLT_MAX, starts and sun starts up to 1e38, any base height, maximum opacity, sun
// exponent -- on random cameras (perspective, reversed Z, infinite far, orthographic; raw, eye and
// radial depth) and poses, with and without a fogged or infinitely far sky, distance or depth,
// precise or fast, float or half storage, over random depths that include 0, 1, the floats next
// to them and values outside [0, 1]. Every output channel must be finite and inside the range the
// formulas allow (channel_range below); alpha passes through. Run on PoCL's two kernels (the CPU
// blocks and the one-pixel kernel GPUs run) and on the scalar path.
//
// Variants are built once per option set (~1 s each cold), so the settings come in shapes: a
// shape fixes what selects the variant (mode, the parts of height fog, sky, projection, depth
// kind, Z direction, storage, precision); each of its cases draws the values at random.
#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "test_support.h"

namespace fogcl::test {
namespace {

using Rng = std::mt19937_64;

double unit(Rng& rng) { return std::uniform_real_distribution<double>(0.0, 1.0)(rng); }
bool coin(Rng& rng, double p = 0.5) { return unit(rng) < p; }
double log_uniform(Rng& rng, double lo, double hi) { return lo * std::pow(hi / lo, unit(rng)); }
// The float next to x that is still finite (above x, or below it at FLT_MAX).
float beside(float x) { return x == FLT_MAX ? std::nextafter(x, 0.0f) : std::nextafter(x, INFINITY); }

// A positive magnitude over float's whole range or a usual one, or one of the ends.
float magnitude(Rng& rng) {
  const double r = unit(rng);
  if (r < 0.05) return FLT_MAX;
  if (r < 0.08) return FLT_MIN;
  if (r < 0.45) return float(log_uniform(rng, 1e-38, 3e38));
  return float(log_uniform(rng, 1e-4, 1e2));
}
float signed_magnitude(Rng& rng) { return coin(rng) ? magnitude(rng) : -magnitude(rng); }
// A distance along the ray (start, sun start): usual ones, up to 1e38, and 2000 (beyond a far
// plane of 1000).
float distance(Rng& rng) {
  const double r = unit(rng);
  if (r < 0.15) return 2000.0f;
  if (r < 0.25) return 1e38f;
  if (r < 0.55) return float(log_uniform(rng, 1e-6, 1e38));
  return float(log_uniform(rng, 0.1, 3000));
}
// A color channel: usual HDR values, zeros, negatives and large ones up to `limit`.
float channel(Rng& rng, float limit) {
  const double r = unit(rng);
  if (r < 0.1) return 0.0f;
  if (r < 0.6) return float(4 * unit(rng));
  if (r < 0.75) return -float(4 * unit(rng));
  return float((coin(rng) ? 1 : -1) * log_uniform(rng, 1e-6, limit));
}

// What selects the variant.
struct Shape {
  FogMode mode = FogMode::height;
  bool step = false;                      // linear: start == end
  bool distance = false, skybox = false, sky_infinite = false;
  int height = 0;                         // HeightFeature bits (kHeightSameIn: in-scattering unset)
  Projection projection = Projection::perspective;
  bool reversed = false;
  DepthKind kind = DepthKind::raw;
  ColorFormat format = ColorFormat::rgba32f;
  Precision precision = Precision::precise;
};

std::string describe(const Shape& s) {
  std::string d = to_string(s.mode);
  if (s.step) d += " step";
  if (s.distance) d += " distance";
  if (s.skybox) d += " fog-skybox";
  if (s.sky_infinite) d += " sky-infinite";
  if (s.mode == FogMode::height) d += " features=" + std::to_string(s.height);
  d += s.projection == Projection::perspective ? " persp" : s.projection == Projection::orthographic ? " ortho" : " inf-far";
  if (s.reversed) d += " revz";
  d += s.kind == DepthKind::raw ? " raw" : s.kind == DepthKind::eye ? " eye" : " radial";
  d += s.format == ColorFormat::rgba16f ? " half" : " float";
  d += s.precision == Precision::fast ? " fast" : " precise";
  return d;
}

// A camera of the shape, with random planes, field of view and pose.
CameraParams draw_camera(const Shape& shape, Rng& rng) {
  CameraParams p;
  if (shape.projection == Projection::orthographic) {
    OrthographicCamera c;
    c.ortho_size = float(log_uniform(rng, 0.1, 1e4));
    c.aspect = float(log_uniform(rng, 0.2, 5));
    c.near_plane = coin(rng, 0.3) ? 0.0f : float(log_uniform(rng, 1e-3, 10));
    c.far_plane = std::max(c.near_plane, 1e-3f) * float(std::pow(10.0, 0.3 + 6.7 * unit(rng)));
    c.reversed_z = shape.reversed;
    p = make_camera_params(c);
  } else {
    PerspectiveCamera c;
    c.fov_y_deg = float(1 + 178 * unit(rng));
    c.aspect = float(log_uniform(rng, 0.2, 5));
    c.near_plane = float(log_uniform(rng, 1e-3, 10));
    c.far_plane = coin(rng, 0.3) ? 1000.0f : c.near_plane * float(std::pow(10.0, 0.3 + 6.7 * unit(rng)));
    c.near_plane = std::min(c.near_plane, 0.3f * c.far_plane);
    c.reversed_z = shape.reversed || shape.projection == Projection::perspective_infinite_far;
    c.infinite_far = shape.projection == Projection::perspective_infinite_far;
    p = make_camera_params(c);
  }
  p.depth_kind = shape.kind;
  p.non_square_pixels = true;  // the aspect is drawn apart from the frame's on purpose: any frustum
  // The pose: heights from usual to 1e30; directions at random, straight up or down, or level.
  CameraPose pose;
  const double r = unit(rng);
  pose.eye = glm::vec3(float(2e3 * unit(rng) - 1e3), r < 0.15 ? signed_magnitude(rng) : float(2e5 * unit(rng) - 1e5),
                       float(2e3 * unit(rng) - 1e3));
  if (std::fabs(pose.eye.y) > 1e30f) pose.eye.y = std::copysign(1e30f, pose.eye.y);
  const double d = unit(rng);
  if (d < 0.15)
    pose.forward = glm::vec3(0.0f, 1.0f, float(0.3 * unit(rng)));  // looking up
  else if (d < 0.25)
    pose.forward = glm::vec3(0.0f, -1.0f, float(0.3 * unit(rng)));
  else if (d < 0.35)
    pose.forward = glm::vec3(float(unit(rng) - 0.5), 0.0f, 1.0f);  // level: a row of horizontal rays
  else
    pose.forward = glm::vec3(float(2 * unit(rng) - 1), float(2 * unit(rng) - 1), float(2 * unit(rng) - 1) + 0.01f);
  pose.up = std::fabs(pose.forward.y) > 0.9f * glm::length(pose.forward) ? glm::vec3(0, 0, 1) : glm::vec3(0, 1, 0);
  p.pose = pose;
  return p;
}

// Random depths of the camera's kind: special values (0, 1, their neighbours, values outside
// [0, 1], the sky, subnormals) and surfaces between near and far.
DepthImage draw_depth(const CameraParams& cam, int w, int h, Rng& rng) {
  DepthImage depth(w, h);
  const double n = std::max(double(cam.near_plane()), 1e-3);
  const double f = std::isfinite(cam.far_plane()) ? cam.far_plane() : 1e7;
  const float raw_special[] = {0.0f, 1.0f, 0x1.fffffep-1f, 0x1p-24f, 0x1p-149f, FLT_MIN, 0.5f, -0.5f, 1.5f, 1e-30f};
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double r = unit(rng);
      const double eye = n * std::pow(f / n, unit(rng));
      float v;
      if (cam.depth_kind != DepthKind::raw) {
        const float special[] = {0.0f, -1.0f, float(n), float(f), float(2 * f), FLT_MAX, 0x1p-149f, float(0.9999 * f)};
        v = r < 0.3 ? special[std::size_t(unit(rng) * 8) % 8] : float(eye * (1 + unit(rng)));
      } else if (r < 0.35) {
        v = raw_special[std::size_t(unit(rng) * 10) % 10];
      } else if (r < 0.5) {
        v = float(unit(rng));
      } else if (cam.projection == Projection::perspective_infinite_far) {
        v = float(n / eye);
      } else if (cam.projection == Projection::orthographic) {
        const double raw = (eye - cam.near_plane()) / (f - cam.near_plane());
        v = float(cam.reversed_z ? 1 - raw : raw);
      } else {
        v = float((f / eye - cam.zbuffer_params.y) / cam.zbuffer_params.x);
      }
      depth.at(x, y) = v;
    }
  return depth;
}

// Settings of the shape with every value drawn at random over its documented range.
FogSettings draw_settings(const Shape& shape, Rng& rng, float color_limit) {
  FogSettings s;
  s.mode = shape.mode;
  s.metric = shape.distance ? FogMetric::distance : FogMetric::depth;
  s.fog_skybox = shape.skybox;
  s.sky = shape.sky_infinite ? SkyDistance::infinite : SkyDistance::far_plane;
  s.precision = shape.precision;
  for (int c = 0; c < 3; ++c) s.color[c] = std::clamp(channel(rng, color_limit), -65504.0f, 65504.0f);
  switch (shape.mode) {
    case FogMode::off:
      break;
    case FogMode::linear: {
      s.start = std::clamp(float(signed_magnitude(rng) * 0.4f), -1e38f, 1e38f);
      s.end = shape.step ? s.start : std::min(s.start + magnitude(rng), FLT_MAX);
      if (!shape.step && !(s.end > s.start)) s.end = std::nextafter(s.start, INFINITY);
      break;
    }
    case FogMode::exp:
    case FogMode::exp2:
      s.density = magnitude(rng);
      break;
    case FogMode::height: {
      HeightFogSettings& h = s.height;
      const int f = shape.height;
      s.density = magnitude(rng);
      if (f & kHeightRgb) {
        glm::vec3 ext(coin(rng, 0.2) ? 0.0f : magnitude(rng), magnitude(rng), coin(rng, 0.2) ? 0.0f : magnitude(rng));
        if (ext.x == ext.y) ext.y = std::nextafter(ext.y, INFINITY);
        h.extinction = ext;
        if (!(f & kHeightSameIn)) {
          glm::vec3 in(coin(rng, 0.3) ? 0.0f : magnitude(rng), magnitude(rng), coin(rng, 0.3) ? 0.0f : magnitude(rng));
          if (in == ext) in.y = beside(in.y);
          h.inscattering = in;
        }
      } else if (!(f & kHeightSameIn)) {
        float g = coin(rng, 0.2) ? 0.0f : magnitude(rng);
        if (g == s.density) g = beside(g);
        h.inscattering = glm::vec3(g);
        if (f & kHeightSun && g == 0.0f) h.inscattering = glm::vec3(beside(s.density));
      }
      if (f & kHeightFalloff) h.falloff = signed_magnitude(rng);
      h.base_height = coin(rng, 0.2) ? signed_magnitude(rng) : float(200 * unit(rng) - 100);
      if (f & kHeightStart) h.start = distance(rng);
      if (f & kHeightCutoff) {
        h.cutoff = std::min(h.start + distance(rng), FLT_MAX);
        if (!(h.cutoff > h.start)) h.cutoff = std::nextafter(h.start, INFINITY);
      }
      if (f & kHeightMaxOpacity) {
        const double r = unit(rng);
        h.max_opacity = r < 0.1 ? 1e-30f : r < 0.2 ? 0x1.fffffep-1f : float(0.01 + 0.98 * unit(rng));
      }
      if (f & kHeightSun) {
        SunLobe sun;
        sun.direction = glm::vec3(float(2 * unit(rng) - 1), float(2 * unit(rng) - 1), float(2 * unit(rng) - 1) + 0.01f);
        for (int c = 0; c < 3; ++c) sun.color[c] = coin(rng, 0.2) ? 0.0f : float(log_uniform(rng, 1e-3, color_limit));
        if (sun.color == glm::vec3(0.0f)) sun.color.x = 1.0f;
        sun.exponent = coin(rng) ? float(log_uniform(rng, 0.1, 1e3)) : magnitude(rng);
        sun.start = (f & kHeightSunStart) ? std::max(distance(rng), std::nextafter(h.start, INFINITY))
                                          : (coin(rng) ? 0.0f : float(h.start * unit(rng)));
        h.sun = sun;
      }
      break;
    }
  }
  return s;
}

ColorImage draw_color(int w, int h, ColorFormat format, float limit, Rng& rng) {
  ColorImage c(w, h, format);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      c.set_pixel(x, y, glm::vec4(channel(rng, limit), channel(rng, limit), channel(rng, limit), float(unit(rng))));
  return c;
}

// The range [lo, hi] a channel may take, from the form of the formulas (before rounding):
//  - linear, exp, exp2 (§2): F + f (c - F) with f in [0, 1]: [min(c, F), max(c, F)];
//  - height (§6.2): c T + F J + S λ J_sun with T, J, λ, J_sun each in [0, 1]:
//    [min(c, 0) + min(F, 0), max(c, 0) + max(F, 0) + S]. Where in-scattering equals extinction
//    J = 1 - T, also under a maximum opacity (max(T, 1 - m) + min(1 - T, m) = 1): a convex blend
//    of c and F, plus the lobe: [min(c, F), max(c, F) + S].
// Rounding is allowed on top: 2^-20 (|c| + |F| + S) (a few float ulps of the terms), and in half
// storage half an ulp of the larger end (2^-11 relative, allowed as 2^-10).
struct Range {
  double lo, hi, tolerance;
};
Range channel_range(const Variant& v, double c, double fog, double sun, bool half) {
  Range r;
  if (v.mode == KernelMode::height && !(v.height_features & kHeightSameIn)) {
    r.lo = std::min(c, 0.0) + std::min(fog, 0.0);
    r.hi = std::max(c, 0.0) + std::max(fog, 0.0) + sun;
  } else {
    r.lo = std::min(c, fog);
    r.hi = std::max(c, fog) + sun;
  }
  r.tolerance = 0x1p-20 * (std::fabs(c) + std::fabs(fog) + sun) +
                (half ? 0x1p-10 * std::max(std::fabs(r.lo), std::fabs(r.hi)) + 0x1p-24 : 0.0);
  return r;
}

struct Tally {
  std::size_t cases = 0, channels = 0, nonfinite = 0, outside = 0, alpha = 0, printed = 0;
  // Per storage (float, half): the max over channels of (distance past the range) / (|c| + |F| + S),
  // negative where every channel lies inside, and where.
  double worst[2] = {-INFINITY, -INFINITY};
  std::string worst_case[2];
};

// Checks one output against its input; `what` names the case for messages.
void check_output(const ColorImage& out, const ColorImage& in, const FogSettings& s, const Variant& v,
                  const std::string& what, Tally& t) {
  const glm::vec3 sun = v.mode == KernelMode::height && (v.height_features & kHeightSun) ? s.height.sun->color
                                                                                      : glm::vec3(0.0f);
  const bool half = in.format() == ColorFormat::rgba16f;
  for (int y = 0; y < in.height(); ++y)
    for (int x = 0; x < in.width(); ++x) {
      const glm::vec4 o = out.pixel(x, y), c = in.pixel(x, y);
      if (std::memcmp(&o.w, &c.w, sizeof o.w) != 0) ++t.alpha;
      for (int k = 0; k < 3; ++k) {
        ++t.channels;
        const Range r = channel_range(v, c[k], s.color[k], sun[k], half);
        const double past = std::isfinite(o[k]) ? std::max(r.lo - o[k], o[k] - r.hi) : INFINITY;
        const double scale = std::max(double(std::fabs(c[k]) + std::fabs(s.color[k]) + sun[k]), 1e-30);
        const bool bad = !std::isfinite(o[k]) || past > r.tolerance;
        if (!std::isfinite(o[k])) ++t.nonfinite;
        else if (bad) ++t.outside;
        if (past / scale > t.worst[half]) {
          t.worst[half] = past / scale;
          char buf[160];
          std::snprintf(buf, sizeof buf, " at %d,%d channel %d: %.9g, range [%.9g, %.9g]", x, y, k, double(o[k]), r.lo, r.hi);
          t.worst_case[half] = what + buf;
        }
        if (bad && t.printed < 8) {
          ++t.printed;
          ADD_FAILURE() << what << " at " << x << "," << y << " channel " << k << ": " << o[k] << " from color " << c[k]
                        << ", not in [" << r.lo << ", " << r.hi << "] (+" << r.tolerance << ")";
        }
      }
    }
}

// The shapes run on every path: those that broke (height fog without falloff, a fogged sky, a
// start or sun start past the far plane; exp at distance 0 with a density near FLT_MAX), one of
// each other mode.
std::vector<Shape> fixed_shapes() {
  std::vector<Shape> v;
  Shape s;
  s.skybox = true;
  s.height = kHeightStart | kHeightSameIn;
  v.push_back(s);  // fogcl apply --mode height --density 0.5 --start 2000 --fog-skybox
  s.height = kHeightRgb | kHeightStart | kHeightSun | kHeightSunStart;
  s.reversed = true;
  s.format = ColorFormat::rgba16f;
  s.precision = Precision::fast;
  v.push_back(s);
  s = Shape{};
  s.sky_infinite = s.skybox = true;
  s.height = kHeightFalloff | kHeightRgb | kHeightStart | kHeightMaxOpacity | kHeightSun | kHeightSunStart;
  s.projection = Projection::perspective_infinite_far;
  s.kind = DepthKind::eye;
  v.push_back(s);
  s = Shape{};
  s.height = kHeightFalloff | kHeightCutoff | kHeightSameIn | kHeightSun;
  s.skybox = true;
  s.projection = Projection::orthographic;
  s.precision = Precision::fast;
  v.push_back(s);
  s = Shape{};
  s.mode = FogMode::exp;
  s.distance = s.skybox = true;
  s.reversed = true;
  v.push_back(s);
  s = Shape{};
  s.mode = FogMode::exp;  // distance 0 at the near plane, a density near FLT_MAX
  s.kind = DepthKind::eye;
  v.push_back(s);
  s = Shape{};
  s.mode = FogMode::exp2;
  s.distance = s.skybox = s.sky_infinite = true;
  s.kind = DepthKind::distance;
  s.format = ColorFormat::rgba16f;
  s.precision = Precision::fast;
  v.push_back(s);
  s = Shape{};
  s.mode = FogMode::linear;
  s.skybox = true;
  s.projection = Projection::orthographic;
  v.push_back(s);
  s = Shape{};
  s.mode = FogMode::linear;
  s.step = s.distance = true;
  s.kind = DepthKind::eye;
  v.push_back(s);
  return v;
}

Shape random_shape(Rng& rng) {
  {
    Shape r;
    const FogMode modes[] = {FogMode::off, FogMode::linear, FogMode::exp, FogMode::exp2, FogMode::height, FogMode::height};
    r.mode = modes[std::size_t(unit(rng) * 6) % 6];
    r.step = r.mode == FogMode::linear && coin(rng, 0.3);
    r.distance = coin(rng);
    r.sky_infinite = coin(rng, 0.3);
    r.skybox = r.sky_infinite || coin(rng);
    if (r.mode == FogMode::height) {
      r.height = int(unit(rng) * 128) & 127;
      if (coin(rng)) r.height |= kHeightSameIn;
      if (!(r.height & kHeightSun)) r.height &= ~kHeightSunStart;
    }
    const double p = unit(rng);
    r.projection = p < 0.6 ? Projection::perspective : p < 0.8 ? Projection::orthographic : Projection::perspective_infinite_far;
    r.reversed = r.projection == Projection::perspective_infinite_far || coin(rng);
    const double k = unit(rng);
    r.kind = k < 0.6 ? DepthKind::raw : k < 0.8 || r.projection == Projection::orthographic ? DepthKind::eye : DepthKind::distance;
    r.format = coin(rng, 0.3) ? ColorFormat::rgba16f : ColorFormat::rgba32f;
    r.precision = coin(rng, 0.3) ? Precision::fast : Precision::precise;
    return r;
  }
}

TEST(FiniteOutput, RandomSettingsOfEveryModeStayFiniteAndInRange) {
  const bool device = runtime() != nullptr;
  if (!device) std::printf("[ note     ] no OpenCL device (%s): the scalar path only\n", runtime_error().c_str());
  Rng rng(20261128);
  const int w = 37, h = 23;  // 37 = two 16-pixel blocks and a tail of 5
  // The fixed shapes and 3 random ones on every path, 25 cases each; 40 more random shapes of
  // 10 cases on the scalar path alone (it builds nothing).
  std::vector<Shape> shapes = fixed_shapes();
  const std::size_t on_device = shapes.size() + 3;
  while (shapes.size() < on_device + 40) shapes.push_back(random_shape(rng));
  Tally t;
  std::size_t variants = 0;
  for (std::size_t n = 0; n < shapes.size(); ++n) {
    const Shape& shape = shapes[n];
    const bool kernels = device && n < on_device;
    const int per_shape = n < on_device ? 25 : 10;
    const Tally before = t;
    Variant first;
    for (int i = 0; i < per_shape; ++i) {
      // Half storage holds 65504: colors, fog and sun colors to 16384 keep every sum inside it.
      const float limit = shape.format == ColorFormat::rgba16f ? 16384.0f : 1e30f;
      const CameraParams cam = draw_camera(shape, rng);
      const FogSettings s = draw_settings(shape, rng, limit);
      const ColorImage color = draw_color(w, h, shape.format, limit, rng);
      const DepthImage depth = draw_depth(cam, w, h, rng);
      const Variant v = select_variant(s, cam, shape.format);
      if (i == 0) {
        first = v;
        ++variants;
      }
      // Every case of a shape is one variant: one program a path.
      ASSERT_EQ(v, first) << describe(shape) << ": case " << i << " is " << fogcl::describe(v) << ", not "
                          << fogcl::describe(first);
      const std::string what = describe(shape) + " case " + std::to_string(i);
      ++t.cases;
      ColorImage out;
      apply_fog_scalar(color, depth, out, cam, s);
      check_output(out, color, s, v, what + " scalar", t);
      if (!kernels) continue;
      for (const KernelPath& path : kernel_paths()) {
        path.pass->apply(color, depth, out, cam, s);
        check_output(out, color, s, v, what + " " + path.name, t);
      }
    }
    std::printf("[ shape    ] %-72s %-8s %6zu non-finite %6zu outside\n", describe(shape).c_str(),
                kernels ? "all" : "scalar", t.nonfinite - before.nonfinite, t.outside - before.outside);
  }
  std::printf("[ measured ] %zu cases in %zu variants, %zu channels: %zu non-finite, %zu outside the range, %zu alpha "
              "changed\n",
              t.cases, variants, t.channels, t.nonfinite, t.outside, t.alpha);
  for (int half = 0; half < 2; ++half)
    std::printf("[ worst    ] %s storage: distance past the range %.3g of |c| + |F| + S (allowed: 2^-20%s), %s\n",
                half ? "half" : "float", t.worst[half], half ? " + half's rounding" : "", t.worst_case[half].c_str());
  EXPECT_EQ(t.nonfinite, 0u);
  EXPECT_EQ(t.outside, 0u);
  EXPECT_EQ(t.alpha, 0u);
}

}  // namespace
}  // namespace fogcl::test
