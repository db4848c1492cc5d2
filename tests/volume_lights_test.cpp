// Local lights in the volume march (docs/volumetric.md#local-lights) against a float64 quadrature
// of the same integral (tests/light_reference.h, none of the formula headers), on the scalar path
// in double and float and on the OpenCL kernel; the extreme placements; and properties of random
// lights: finite, never darker than without them, culled lights bit-identical to none.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>

#include <glm/geometric.hpp>

#include "fogcl/error.h"
#include "light_reference.h"
#include "volume_support.h"

namespace fogcl::test {
namespace {

namespace ref = light_reference;

constexpr int kW = 32, kH = 20;
const glm::dvec3 kScene{0.05, 0.1, 0.15};
constexpr double kFar = 200.0;  // the sky's rays: the reference integrates to here (past every medium)

struct LightFrame {
  ColorImage color;
  DepthImage depth;
  CameraParams params;
  VolumeScene scene;
  std::vector<ref::Medium> media;
};

// Sky everywhere, camera at the origin looking along +z; homogeneous spheres lit by the lights
// alone (main light and ambient black).
LightFrame light_frame(const std::vector<ref::Medium>& media, const std::vector<LocalLight>& lights) {
  LightFrame f;
  f.color = uniform_image(kW, kH, ColorFormat::rgba32f, glm::vec4(glm::vec3(kScene), 1.0f));
  f.depth = DepthImage(kW, kH, 1.0f);
  PerspectiveCamera cam;
  cam.fov_y_deg = 60.0f;
  cam.aspect = float(kW) / kH;
  cam.near_plane = 0.3f;
  cam.far_plane = 100.0f;
  f.params = make_camera_params(cam);
  for (const ref::Medium& m : media) {
    FogVolume v;
    v.center = glm::vec3(m.center);
    v.radius = float(m.radius);
    v.density = float(m.sigma_t);
    v.noise = false;
    v.fade_edge = v.fade_y = v.proximity_fade = 0.0f;
    v.max_y = 1e6f;
    v.albedo = glm::vec3(m.albedo);
    v.ambient = glm::vec3(0.0f);
    v.anisotropy = float(m.g);
    f.scene.volumes.push_back(v);
  }
  f.scene.light.color = glm::vec3(0.0f);
  f.scene.lights = lights;
  f.media = media;
  return f;
}

VolumeSettings light_settings(int steps) {
  VolumeSettings s;
  s.integrator = VolumeIntegrator::physical;
  s.resolution_divisor = 1;
  s.steps = steps;
  s.jitter = false;
  return s;
}

// Pixel (x, y)'s ray as the pass defines it (docs/volumetric.md: from the near plane through the
// pixel's centre on the bilinear frustum corners).
void pixel_ray(const CameraParams& p, int x, int y, glm::dvec3& origin, glm::dvec3& dir) {
  const double u = (x + 0.5) / kW, v = 1.0 - (y + 0.5) / kH;
  const auto& k = p.frustum_corners;
  glm::dvec3 corner;
  for (int i = 0; i < 3; ++i) {
    const double left = k[kBottomLeft][i] + (double(k[kTopLeft][i]) - k[kBottomLeft][i]) * v;
    const double right = k[kBottomRight][i] + (double(k[kTopRight][i]) - k[kBottomRight][i]) * v;
    corner[i] = left + (right - left) * u;
  }
  origin = corner * (double(p.near_plane()) / corner.z);
  dir = glm::normalize(corner);
}

struct Errors {
  double worst = 0;    // max |got - want| / (want's light + 1e-3 x the frame's brightest light)
  double brightest = 0;
  bool finite = true;
};

// The reference image: scene x T + the lights' in-scattering, per pixel.
std::vector<glm::dvec3> reference_image(const LightFrame& f, long panels) {
  std::vector<glm::dvec3> out(std::size_t(kW) * kH);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      glm::dvec3 o, d;
      pixel_ray(f.params, x, y, o, d);
      out[std::size_t(y) * kW + x] = kScene * ref::transmittance(o, d, kFar, f.media) +
                                      ref::inscattered(o, d, kFar, f.media, f.scene.lights, panels);
    }
  return out;
}

template <class Get>
Errors compare(const std::vector<glm::dvec3>& want, const Get& got) {
  Errors e;
  for (const glm::dvec3& w : want) e.brightest = std::max({e.brightest, w.x, w.y, w.z});
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const glm::dvec3 w = want[std::size_t(y) * kW + x], g = got(x, y);
      for (int c = 0; c < 3; ++c) {
        if (!std::isfinite(g[c])) e.finite = false;
        e.worst = std::max(e.worst, std::fabs(g[c] - w[c]) / (w[c] + 1e-3 * e.brightest));
      }
    }
  return e;
}

struct Paths {
  Errors scalar_double, scalar_float, kernel;
  bool device = false;
};

Paths run_all(const LightFrame& f, const VolumeSettings& s, const std::vector<glm::dvec3>& want) {
  Paths r;
  const VolumeResult<double> d = volumes_scalar<double>(f.color, f.depth, f.params, f.scene, s);
  r.scalar_double = compare(want, [&](int x, int y) {
    const std::size_t i = 4 * (std::size_t(y) * kW + x);
    return glm::dvec3(d.rgba[i], d.rgba[i + 1], d.rgba[i + 2]);
  });
  ColorImage out;
  apply_volumes_scalar(f.color, f.depth, out, f.params, f.scene, s);
  r.scalar_float = compare(want, [&](int x, int y) { return glm::dvec3(glm::vec3(out.pixel(x, y))); });
  if (runtime() != nullptr) {
    r.device = true;
    ColorImage k;
    VolumePass(*runtime()).apply(f.color, f.depth, k, f.params, f.scene, s);
    r.kernel = compare(want, [&](int x, int y) { return glm::dvec3(glm::vec3(k.pixel(x, y))); });
  }
  return r;
}

LocalLight point_at(glm::vec3 p, float intensity, float range, float radius = 0.05f) {
  LocalLight l;
  l.position = p;
  l.color = glm::vec3(1.0f, 0.8f, 0.6f);
  l.intensity = intensity;
  l.range = range;
  l.radius = radius;
  return l;
}

LocalLight spot_at(glm::vec3 p, glm::vec3 axis, float inner, float outer, float intensity, float range) {
  LocalLight l = point_at(p, intensity, range);
  l.kind = LightKind::spot;
  l.direction = axis;
  l.inner_angle = inner;
  l.outer_angle = outer;
  return l;
}

struct Case {
  const char* name;
  std::vector<ref::Medium> media;
  std::vector<LocalLight> lights;
  double budget_double, budget_float;  // relative to the light at the pixel (+1e-3 of the brightest)
};

std::vector<Case> cases() {
  const ref::Medium fog{{0.3, 0.2, 8.0}, 4.0, 0.3, {0.9, 0.8, 0.7}, 0.0};
  const ref::Medium forward{{0.3, 0.2, 8.0}, 4.0, 0.3, {0.9, 0.8, 0.7}, 0.6};
  const ref::Medium back{{-1.0, -0.5, 10.0}, 3.0, 0.8, {0.5, 0.7, 0.9}, -0.3};
  return {
      {"point-inside-isotropic", {fog}, {point_at({0.5f, 0.4f, 7.0f}, 20.0f, 6.0f)}, 2e-3, 3e-3},
      {"point-inside-anisotropic", {forward}, {point_at({0.5f, 0.4f, 7.0f}, 20.0f, 6.0f)}, 2e-2, 2e-2},
      {"spot-cone", {fog}, {spot_at({0.0f, 3.0f, 8.0f}, {0.1f, -1.0f, 0.2f}, 15.0f, 30.0f, 40.0f, 9.0f)}, 2e-2, 2e-2},
      {"two-lights-overlapping-volumes",
       {forward, back},
       {point_at({-1.0f, 0.0f, 9.0f}, 10.0f, 5.0f, 0.2f), spot_at({2.0f, 1.0f, 4.0f}, {-0.3f, -0.2f, 1.0f}, 0.0f, 20.0f, 30.0f, 12.0f)},
       2e-2, 2e-2},
  };
}

// The march against the quadrature: 64 steps per ray, the light's stretch of a segment in pieces
// of at most pi/32 seen from the light. The budgets are the per-piece approximation's (phase,
// cone, window and transmittance at one point of each piece; docs/volumetric.md#local-lights).
TEST(VolumeLights, MarchMatchesQuadrature) {
  for (const Case& c : cases()) {
    const LightFrame f = light_frame(c.media, c.lights);
    const std::vector<glm::dvec3> want = reference_image(f, 300);
    const Paths r = run_all(f, light_settings(64), want);
    std::printf("  %-32s worst relative error: scalar<double> %.3g, scalar<float> %.3g, kernel %s (brightest %.3g)\n",
                c.name, r.scalar_double.worst, r.scalar_float.worst,
                r.device ? std::to_string(r.kernel.worst).c_str() : "(no device)", r.scalar_double.brightest);
    EXPECT_TRUE(r.scalar_double.finite && r.scalar_float.finite && (!r.device || r.kernel.finite)) << c.name;
    EXPECT_LE(r.scalar_double.worst, c.budget_double) << c.name;
    EXPECT_LE(r.scalar_float.worst, c.budget_float) << c.name;
    if (r.device) {
      EXPECT_LE(r.kernel.worst, c.budget_float) << c.name;
    }
  }
}

}  // namespace
}  // namespace fogcl::test
