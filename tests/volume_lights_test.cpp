// Local lights in the volume march (docs/volumetric.md#local-lights) against a float64 quadrature
// of the same integral (tests/light_reference.h, none of the formula headers), on the scalar path
// in double and float and on the OpenCL kernel; the extreme placements; properties of random
// lights: finite, never darker than without them, culled lights bit-identical to none; and in a
// marched height fog whose extinction differs per channel, each channel as that channel's grey fog.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>

#include <glm/geometric.hpp>

#include "fogcl/depth_kinds.h"
#include "fogcl/error.h"
#include "light_reference.h"
#include "volume/volume_formulas.h"
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
  Errors scalar_double, scalar_float, kernel, one_pixel;  // kernel: the device's own (CPU: 16 lanes)
  bool device = false, cpu = false;                       // cpu: one_pixel ran (the one-pixel kernel)
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
    if (runtime()->is_cpu()) {
      r.cpu = true;
      CpuCodegen one_pixel;
      one_pixel.one_pixel_per_work_item = true;
      VolumePass(*runtime(), nullptr, one_pixel).apply(f.color, f.depth, k, f.params, f.scene, s);
      r.one_pixel = compare(want, [&](int x, int y) { return glm::dvec3(glm::vec3(k.pixel(x, y))); });
    }
  }
  return r;
}

// Prints a case's worst errors and checks them against its budgets.
void check_paths(const char* name, const Paths& r, double budget_double, double budget_float) {
  std::printf("  %-32s worst relative error: scalar<double> %.3g, scalar<float> %.3g, kernel %s%s (brightest %.3g)\n",
              name, r.scalar_double.worst, r.scalar_float.worst,
              r.device ? std::to_string(r.kernel.worst).c_str() : "(no device)",
              r.cpu ? (", one pixel per work-item " + std::to_string(r.one_pixel.worst)).c_str() : "",
              r.scalar_double.brightest);
  EXPECT_TRUE(r.scalar_double.finite && r.scalar_float.finite && (!r.device || r.kernel.finite) &&
              (!r.cpu || r.one_pixel.finite))
      << name;
  EXPECT_LE(r.scalar_double.worst, budget_double) << name;
  EXPECT_LE(r.scalar_float.worst, budget_float) << name;
  if (r.device) {
    EXPECT_LE(r.kernel.worst, budget_float) << name;
  }
  if (r.cpu) {
    EXPECT_LE(r.one_pixel.worst, budget_float) << name;
  }
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
      {"point-inside-isotropic", {fog}, {point_at({0.5f, 0.4f, 7.0f}, 20.0f, 6.0f)}, 1e-3, 1e-3},
      {"point-inside-anisotropic", {forward}, {point_at({0.5f, 0.4f, 7.0f}, 20.0f, 6.0f)}, 2e-3, 2e-3},
      {"spot-cone", {fog}, {spot_at({0.0f, 3.0f, 8.0f}, {0.1f, -1.0f, 0.2f}, 15.0f, 30.0f, 40.0f, 9.0f)}, 1e-2, 1e-2},
      {"two-lights-overlapping-volumes",
       {forward, back},
       {point_at({-1.0f, 0.0f, 9.0f}, 10.0f, 5.0f, 0.2f), spot_at({2.0f, 1.0f, 4.0f}, {-0.3f, -0.2f, 1.0f}, 0.0f, 20.0f, 30.0f, 12.0f)},
       1e-2, 1e-2},
  };
}

// The march against the quadrature: 64 steps per ray, the light's stretch of a segment in pieces
// of at most pi/32 seen from the light. The budgets are the per-piece approximation's (phase,
// cone, window and transmittance at one point of each piece; docs/volumetric.md#local-lights).
TEST(VolumeLights, MarchMatchesQuadrature) {
  for (const Case& c : cases()) {
    const LightFrame f = light_frame(c.media, c.lights);
    const std::vector<glm::dvec3> want = reference_image(f, 300);
    check_paths(c.name, run_all(f, light_settings(64), want), c.budget_double, c.budget_float);
  }
}


// The ray of the pixel at the frame's centre, a point on it at distance t (in float: on the ray to
// float rounding).
glm::vec3 on_centre_ray(const CameraParams& p, double t) {
  glm::dvec3 o, d;
  pixel_ray(p, kW / 2, kH / 2, o, d);
  return glm::vec3(o + d * t);
}

// Placements where a sampled inverse square would be a spike or a division by ~0: finite on every
// path and within the same budgets of the quadrature.
TEST(VolumeLights, ExtremePlacementsAreFiniteAndMatchQuadrature) {
  const ref::Medium fog{{0.3, 0.2, 8.0}, 4.0, 0.3, {0.9, 0.8, 0.7}, 0.3};
  const ref::Medium around_camera{{0.0, 0.0, 1.0}, 5.0, 0.2, {0.8, 0.8, 0.8}, 0.0};
  const CameraParams params = light_frame({}, {}).params;
  LocalLight near_sample = point_at(on_centre_ray(params, 7.0) + glm::vec3(1e-4f, 0.0f, 0.0f), 1.0f, 5.0f, 1e-4f);
  LocalLight on_ray = point_at(on_centre_ray(params, 8.0), 2.0f, 5.0f, 1e-3f);
  LocalLight at_camera = point_at(glm::vec3(0.0f), 3.0f, 6.0f, 0.01f);
  LocalLight behind = point_at({0.0f, 0.5f, -2.0f}, 5.0f, 7.0f);
  LocalLight far_range = point_at({1.0f, 1.0f, 6.0f}, 1.0f, 1e6f);
  LocalLight bright = point_at({-1.0f, 0.0f, 9.0f}, 1e6f, 4.0f);
  const std::vector<Case> extreme = {
      {"light 1e-4 from the centre ray", {fog}, {near_sample}, 1e-2, 1e-2},
      {"light on the centre ray", {fog}, {on_ray}, 1e-2, 1e-2},
      {"light at the camera", {around_camera}, {at_camera}, 1e-2, 1e-2},
      {"light behind the camera", {around_camera}, {behind}, 1e-2, 1e-2},
      {"range 1e6", {fog}, {far_range}, 1e-2, 1e-2},
      {"intensity 1e6", {fog}, {bright}, 1e-2, 1e-2},
  };
  for (const Case& c : extreme) {
    const LightFrame f = light_frame(c.media, c.lights);
    const std::vector<glm::dvec3> want = reference_image(f, 300);
    check_paths(c.name, run_all(f, light_settings(32), want), c.budget_double, c.budget_float);
  }
  // A medium of zero density scatters nothing: the lights leave the frame as it is.
  const LightFrame empty = light_frame({{{0.3, 0.2, 8.0}, 4.0, 0.0, {0.9, 0.8, 0.7}, 0.0}}, {on_ray, bright});
  ColorImage out;
  apply_volumes_scalar(empty.color, empty.depth, out, empty.params, empty.scene, light_settings(32));
  EXPECT_EQ(std::memcmp(out.data(), empty.color.data(), empty.color.size_bytes()), 0);
  if (runtime() != nullptr) {
    VolumePass(*runtime()).apply(empty.color, empty.depth, out, empty.params, empty.scene, light_settings(32));
    EXPECT_EQ(std::memcmp(out.data(), empty.color.data(), empty.color.size_bytes()), 0);
  }
}

// The frame on the kernel where there is a device, else on the scalar path in float.
ColorImage render(const LightFrame& f, const VolumeSettings& s) {
  ColorImage out;
  if (runtime() != nullptr)
    VolumePass(*runtime()).apply(f.color, f.depth, out, f.params, f.scene, s);
  else
    apply_volumes_scalar(f.color, f.depth, out, f.params, f.scene, s);
  return out;
}

bool same_bits(const ColorImage& a, const ColorImage& b) {
  return a.size_bytes() == b.size_bytes() && std::memcmp(a.data(), b.data(), a.size_bytes()) == 0;
}

// Random lights in random media: finite, never darker than the same frame without lights (they
// only add radiance), and a light that cannot add any (black, its range short of every volume, or
// its range meeting a volume only outside the view) leaves the frame's bits as they were. A spot
// light whose inner cone holds the whole volume gives the point light's bits.
TEST(VolumeLights, RandomLightsOnlyAddAndCulledLightsChangeNoBit) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const auto in_box = [&](float lo, float hi) { return glm::vec3(lo + (hi - lo) * u(rng), lo + (hi - lo) * u(rng), 4.0f + 10.0f * u(rng)); };
  int frames = 0, darker = 0, nonfinite = 0, changed = 0;
  double most_added = 0;
  for (int i = 0; i < 12; ++i) {
    std::vector<ref::Medium> media;
    for (int m = 0; m < 1 + i % 2; ++m)
      media.push_back({glm::dvec3(in_box(-3.0f, 3.0f)), 1.0 + 3.0 * u(rng), 2.0 * u(rng),
                       glm::dvec3(u(rng), u(rng), u(rng)), 1.8 * u(rng) - 0.9});
    std::vector<LocalLight> lights;
    for (int k = 0; k < 1 + i % 4; ++k) {
      LocalLight l = point_at(in_box(-4.0f, 4.0f), 100.0f * u(rng), 0.5f + 10.0f * u(rng), 0.001f + 0.2f * u(rng));
      if (u(rng) < 0.5f) {
        l.kind = LightKind::spot;
        l.direction = in_box(-1.0f, 1.0f) - glm::vec3(0.0f, 0.0f, 9.0f);
        l.outer_angle = 1.0f + 89.0f * u(rng);
        l.inner_angle = l.outer_angle * u(rng);
      }
      lights.push_back(l);
    }
    const VolumeSettings s = light_settings(8 + 16 * (i % 3));
    const LightFrame lit = light_frame(media, lights), dark = light_frame(media, {});
    const ColorImage with = render(lit, s), without = render(dark, s);
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x)
        for (int c = 0; c < 3; ++c) {
          const float a = with.pixel(x, y)[c], b = without.pixel(x, y)[c];
          nonfinite += !std::isfinite(a);
          darker += a < b;
          most_added = std::max(most_added, double(a) - double(b));
        }
    // Lights that add nothing: black, out of range of every volume.
    LightFrame more = lit;
    LocalLight black = lights[0];
    black.intensity = 0.0f;
    const LocalLight unreachable = point_at({500.0f, 0.0f, 10.0f}, 1e3f, 50.0f);
    more.scene.lights.insert(more.scene.lights.end(), {black, unreachable});
    changed += !same_bits(render(more, s), with);
    ++frames;
  }
  // A light whose range meets a volume only beside the view is packed and met by no ray: the
  // kernel's per-ray culling leaves the bits of the frame.
  const ref::Medium wide{{12.0, 0.0, 8.0}, 9.0, 0.4, {0.9, 0.9, 0.9}, 0.0};
  const LocalLight seen = point_at({4.0f, 0.0f, 8.0f}, 50.0f, 6.0f);
  const LocalLight beside = point_at({22.0f, 0.0f, 8.0f}, 1e3f, 5.0f);  // x >= 17: outside the frustum
  changed += !same_bits(render(light_frame({wide}, {seen, beside}), light_settings(16)),
                        render(light_frame({wide}, {seen}), light_settings(16)));
  // The cone: a spot high above the first volume, its inner cone holding the whole sphere.
  const ref::Medium m{{0.0, 0.0, 8.0}, 3.0, 0.5, {0.9, 0.9, 0.9}, 0.4};
  const LocalLight point = point_at({0.0f, 20.0f, 8.0f}, 500.0f, 40.0f);
  LocalLight spot = point;
  spot.kind = LightKind::spot;
  spot.direction = {0.0f, -1.0f, 0.0f};
  spot.inner_angle = 25.0f;  // the sphere subtends 8.7 degrees
  spot.outer_angle = 40.0f;
  const bool cone_is_point = same_bits(render(light_frame({m}, {spot}), light_settings(16)),
                                       render(light_frame({m}, {point}), light_settings(16)));
  std::printf("  %d frames of random lights (%s): %d darker and %d non-finite channels; most radiance added %.3g; "
              "%d frames changed by culled lights; spot within its inner cone %s the point light\n",
              frames, runtime() != nullptr ? "kernel" : "scalar", darker, nonfinite, most_added, changed,
              cone_is_point ? "==" : "!=");
  EXPECT_EQ(darker, 0);
  EXPECT_EQ(nonfinite, 0);
  EXPECT_GT(most_added, 0.0);
  EXPECT_EQ(changed, 0);
  EXPECT_TRUE(cone_is_point);
}

// The stylized integrator has no per-sample light: it refuses local lights, naming the rule; so
// does the march for more lights than it holds.
TEST(VolumeLights, StylizedRefusesLocalLights) {
  LightFrame f = light_frame({{{0.3, 0.2, 8.0}, 4.0, 0.3, {0.9, 0.8, 0.7}, 0.0}}, {point_at({0.0f, 0.0f, 8.0f}, 1.0f, 5.0f)});
  VolumeSettings s = light_settings(16);
  s.integrator = VolumeIntegrator::stylized;
  ColorImage out;
  try {
    apply_volumes_scalar(f.color, f.depth, out, f.params, f.scene, s);
    ADD_FAILURE() << "stylized with lights was accepted";
  } catch (const Error& e) {
    std::printf("  %s\n", e.what());
    EXPECT_NE(std::string(e.what()).find("physical integrator"), std::string::npos);
  }
  // More lights reaching a medium than the march's private arrays hold: an error that says so.
  f.scene.lights.assign(kMaxLocalLights + 1, point_at({0.0f, 0.0f, 8.0f}, 1.0f, 5.0f));
  try {
    apply_volumes_scalar(f.color, f.depth, out, f.params, f.scene, light_settings(16));
    ADD_FAILURE() << "33 lights were accepted";
  } catch (const Error& e) {
    std::printf("  %s\n", e.what());
    EXPECT_NE(std::string(e.what()).find("33 local lights reach a visible medium in this frame; at most 32"),
              std::string::npos);
  }
}

// validate(LocalLight) names the light's index, the value and the rule.
TEST(VolumeLights, BadLightsAreNamed) {
  struct Bad {
    const char* want;
    LocalLight light;
  };
  LocalLight base;
  std::vector<Bad> bad;
  auto with = [&](const char* want, auto change) {
    LocalLight l = base;
    change(l);
    bad.push_back({want, l});
  };
  with("light 3: position must be finite", [](LocalLight& l) { l.position.y = NAN; });
  with("light 3: color must be RGB, finite and >= 0", [](LocalLight& l) { l.color.z = -1.0f; });
  with("light 3: intensity must be finite and >= 0", [](LocalLight& l) { l.intensity = INFINITY; });
  with("light 3: range must be finite and in (0, 1e15]", [](LocalLight& l) { l.range = 0.0f; });
  with("light 3: radius must be finite and in [1e-6, range]", [](LocalLight& l) { l.radius = 20.0f; });
  with("light 3: radius must be finite and in [1e-6, range]", [](LocalLight& l) { l.radius = 1e-7f; });
  with("light 3: intensity * max(color) * max(1, 1 / radius^2) must be <= 1e30",
       [](LocalLight& l) { l.intensity = 1e25f, l.radius = 1e-5f; });
  with("light 3: direction must be a finite non-zero vector",
       [](LocalLight& l) { l.kind = LightKind::spot, l.direction = glm::vec3(0.0f); });
  with("light 3: outer_angle must be in (0, 90] degrees",
       [](LocalLight& l) { l.kind = LightKind::spot, l.outer_angle = 95.0f; });
  with("light 3: inner_angle must be in [0, outer_angle] degrees",
       [](LocalLight& l) { l.kind = LightKind::spot, l.inner_angle = 50.0f; });
  for (const Bad& b : bad) {
    try {
      validate(b.light, 3);
      ADD_FAILURE() << "accepted: " << b.want;
    } catch (const Error& e) {
      EXPECT_EQ(std::string(e.what()).rfind(b.want, 0), 0u) << e.what();
    }
  }
  LocalLight point_with_cone = base;
  point_with_cone.outer_angle = 95.0f;  // a point light has no cone: its angles are not read
  EXPECT_NO_THROW(validate(point_with_cone, 0));
}


// The marched height fog (docs/DESIGN.md §6.6): homogeneous (falloff 0), black (F = 0, no sun
// lobe) so the lights are its only light, in front of a wall at eye depth 30. To the reference it
// is a sphere around the eye larger than the view with sigma_t = beta_ext and albedo
// beta_in / beta_ext, isotropic; the fog starts at the eye, the pass's rays at the near plane.
TEST(VolumeLights, HeightFogGlowsAsTheQuadratureSays) {
  constexpr float kWall = 30.0f;
  const glm::dvec3 beta_ext(0.08), beta_in(0.05, 0.06, 0.07);
  const ref::Medium fog_sphere{{0.0, 0.0, 0.0}, 1e3, beta_ext.x, beta_in / beta_ext, 0.0};
  const ref::Medium volume{{0.5, 0.0, 12.0}, 3.0, 0.4, {0.9, 0.8, 0.7}, 0.5};
  struct HeightCase {
    const char* name;
    bool with_volume;
    std::vector<LocalLight> lights;
  };
  const std::vector<HeightCase> height_cases = {
      {"height fog, point light", false, {point_at({1.0f, 0.5f, 8.0f}, 20.0f, 12.0f, 0.1f)}},
      {"height fog and a volume, spot light", true,
       {spot_at({-1.0f, 4.0f, 10.0f}, {0.1f, -1.0f, 0.3f}, 10.0f, 35.0f, 60.0f, 20.0f)}},
      {"height fog, light at the camera", false, {point_at({0.0f, 0.0f, 0.0f}, 5.0f, 8.0f, 0.02f)}},
  };
  for (const HeightCase& c : height_cases) {
    LightFrame f = light_frame(c.with_volume ? std::vector<ref::Medium>{volume} : std::vector<ref::Medium>{}, c.lights);
    DepthImage eye(kW, kH, kWall);
    to_raw_depth(eye, DepthKind::eye, f.params);
    f.depth = eye;
    VolumeSettings s = light_settings(48);
    FogSettings fog;
    fog.mode = FogMode::height;
    fog.color = glm::vec3(0.0f);
    fog.height.extinction = glm::vec3(beta_ext);
    fog.height.inscattering = glm::vec3(beta_in);
    s.height_fog = fog;
    std::vector<ref::Medium> media = f.media;
    media.push_back(fog_sphere);
    std::vector<glm::dvec3> want(std::size_t(kW) * kH);
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x) {
        glm::dvec3 o, d;
        pixel_ray(f.params, x, y, o, d);
        const double t_end = double(kWall) / d.z;  // from the eye (the origin) to the wall
        want[std::size_t(y) * kW + x] = kScene * ref::transmittance(glm::dvec3(0.0), d, t_end, media) +
                                        ref::inscattered(glm::dvec3(0.0), d, t_end, media, f.scene.lights, 300);
      }
    check_paths(c.name, run_all(f, s, want), 1e-2, 1e-2);
  }
}

// A marched height fog whose extinction differs per channel, in-scattering equal to extinction:
// channel c of the frame is channel c of the same frame under the grey fog beta_c in all three
// channels (volumes, lights, main light, fog and sun colours unchanged), on the kernel and the
// scalar path in float and double; random fogs (falloff, start, cut-off, sky), volumes and point
// and spot lights. The lights add finite, non-negative light to the per-channel frame.
struct RgbFogCase {
  LightFrame frame;
  VolumeSettings settings;
  glm::vec3 beta;
};

RgbFogCase random_rgb_fog_case(std::mt19937& rng, int i) {
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const auto in_box = [&](float lo, float hi) {
    return glm::vec3(lo + (hi - lo) * u(rng), lo + (hi - lo) * u(rng), 3.0f + 14.0f * u(rng));
  };
  std::vector<ref::Medium> media;
  for (int m = 0; m < 1 + i % 2; ++m)
    media.push_back({glm::dvec3(in_box(-3.0f, 3.0f)), 1.0 + 3.0 * u(rng), 1.5 * u(rng),
                     glm::dvec3(u(rng), u(rng), u(rng)), 1.6 * u(rng) - 0.8});
  std::vector<LocalLight> lights;
  for (int k = 0; k < 2 + i % 2; ++k) {
    LocalLight l = point_at(in_box(-4.0f, 4.0f), 5.0f + 60.0f * u(rng), 3.0f + 12.0f * u(rng), 0.01f + 0.2f * u(rng));
    l.color = glm::vec3(0.3f + 0.7f * u(rng), 0.3f + 0.7f * u(rng), 0.3f + 0.7f * u(rng));
    if (k % 2) {  // every frame has a point and a spot light
      l.kind = LightKind::spot;
      l.direction = in_box(-2.0f, 2.0f) - l.position;
      l.outer_angle = 10.0f + 80.0f * u(rng);
      l.inner_angle = l.outer_angle * u(rng);
    }
    lights.push_back(l);
  }
  RgbFogCase c{light_frame(media, lights), light_settings(8 + 8 * (i % 5)), {}};
  LightFrame& f = c.frame;
  f.scene.light.direction = glm::vec3(0.3f, 0.4f, 1.0f);
  f.scene.light.color = glm::vec3(0.8f, 0.7f, 0.6f) * u(rng);
  for (FogVolume& v : f.scene.volumes) v.ambient = glm::vec3(0.1f * u(rng));
  // A wall from eye depth 8 (left) to 40 (right); the last columns are sky.
  DepthImage eye(kW, kH, 0.0f);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) eye.data()[std::size_t(y) * kW + x] = 8.0f + 32.0f * x / (kW - 1);
  to_raw_depth(eye, DepthKind::eye, f.params);
  for (int y = 0; y < kH; ++y)
    for (int x = kW - 5; x < kW; ++x) eye.data()[std::size_t(y) * kW + x] = 1.0f;
  f.depth = eye;
  c.beta = glm::vec3(0.005f + 0.12f * u(rng), 0.005f + 0.12f * u(rng), 0.005f + 0.12f * u(rng));
  FogSettings fog;
  fog.mode = FogMode::height;
  fog.color = glm::vec3(u(rng), u(rng), u(rng));
  fog.height.falloff = i % 3 == 0 ? 0.0f : 0.3f * u(rng) - 0.1f;
  fog.height.base_height = 2.0f * u(rng) - 1.0f;
  // Volumes also before the fog's start and past its cut-off: their light dimmed by the whole
  // fog's depth per channel, or by none of it.
  fog.height.start = i % 4 >= 2 ? 8.0f * u(rng) : 0.0f;
  if (i % 5 == 1 || i % 5 == 3) fog.height.cutoff = fog.height.start + 4.0f + 8.0f * u(rng);
  fog.fog_skybox = i % 2 == 0;
  SunLobe sun;
  sun.direction = f.scene.light.direction;
  sun.color = glm::vec3(u(rng), u(rng), u(rng));
  sun.exponent = 4.0f + 8.0f * u(rng);
  fog.height.sun = sun;
  fog.height.extinction = fog.height.inscattering = c.beta;
  c.settings.height_fog = fog;
  c.settings.resolution_divisor = i % 3 == 2 ? 2 : 1;
  c.settings.jitter = i % 2 == 1;
  f.scene.frame_index = unsigned(i);
  return c;
}

// The frame of one case on each path: kernel (where there is a device), scalar float and double.
struct RgbFogFrames {
  ColorImage kernel, scalar_float;
  std::vector<double> scalar_double;
  std::string kernel_options;
};

RgbFogFrames render_rgb_fog(const LightFrame& f, const VolumeSettings& s) {
  RgbFogFrames r;
  if (runtime() != nullptr) {
    static VolumePass pass(*runtime());
    pass.apply(f.color, f.depth, r.kernel, f.params, f.scene, s);
    r.kernel_options = pass.last_march_options();
  }
  apply_volumes_scalar(f.color, f.depth, r.scalar_float, f.params, f.scene, s);
  const VolumeResult<double> d = volumes_scalar<double>(f.color, f.depth, f.params, f.scene, s);
  r.scalar_double.assign(d.rgba.begin(), d.rgba.end());
  return r;
}

// The VOL_FEATURES of a march's build options.
int march_features(const std::string& options) {
  const std::size_t at = options.find("VOL_FEATURES=");
  return at == std::string::npos ? 0 : std::stoi(options.substr(at + 13));
}

TEST(VolumeLights, PerChannelFogIsEachChannelsGreyFog) {
  std::mt19937 rng(11);
  // |per-channel - grey| / max(1, |grey|), worst over pixels and channels, per path
  double worst_kernel = 0, worst_float = 0, worst_double = 0, most_added = 0;
  int darker = 0, nonfinite = 0, rgb_variants = 0, frames = 0;
  const auto err = [](double a, double b) {
    const double e = std::fabs(a - b) / std::max(1.0, std::fabs(b));
    return std::isnan(e) ? INFINITY : e;
  };
  for (int i = 0; i < 8; ++i) {
    const RgbFogCase c = random_rgb_fog_case(rng, i);
    const RgbFogFrames rgb = render_rgb_fog(c.frame, c.settings);
    const int features = march_features(rgb.kernel_options);
    rgb_variants += (features & VOL_FEATURE_HEIGHT_RGB) && (features & VOL_FEATURE_LIGHTS) &&
                    (features & VOL_FEATURE_SPOT);
    for (int ch = 0; ch < 3; ++ch) {
      VolumeSettings grey = c.settings;
      grey.height_fog->height.extinction = grey.height_fog->height.inscattering = glm::vec3(c.beta[ch]);
      const RgbFogFrames g = render_rgb_fog(c.frame, grey);
      for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
          const std::size_t at = 4 * (std::size_t(y) * kW + x) + ch;
          worst_double = std::max(worst_double, err(rgb.scalar_double[at], g.scalar_double[at]));
          worst_float = std::max(worst_float, err(rgb.scalar_float.pixel(x, y)[ch], g.scalar_float.pixel(x, y)[ch]));
          if (runtime() != nullptr)
            worst_kernel = std::max(worst_kernel, err(rgb.kernel.pixel(x, y)[ch], g.kernel.pixel(x, y)[ch]));
        }
    }
    // The lights' part of the per-channel frame: finite and >= 0 on every path.
    LightFrame dark = c.frame;
    dark.scene.lights.clear();
    const RgbFogFrames unlit = render_rgb_fog(dark, c.settings);
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x)
        for (int ch = 0; ch < 3; ++ch) {
          const std::size_t at = 4 * (std::size_t(y) * kW + x) + ch;
          std::vector<std::pair<double, double>> pairs = {
              {rgb.scalar_double[at], unlit.scalar_double[at]},
              {rgb.scalar_float.pixel(x, y)[ch], unlit.scalar_float.pixel(x, y)[ch]}};
          if (runtime() != nullptr) pairs.push_back({rgb.kernel.pixel(x, y)[ch], unlit.kernel.pixel(x, y)[ch]});
          for (const auto& [with, without] : pairs) {
            nonfinite += !std::isfinite(with);
            darker += with < without;
            most_added = std::max(most_added, with - without);
          }
        }
    ++frames;
  }
  char kernel[32] = "(no device)";
  if (runtime() != nullptr) std::snprintf(kernel, sizeof kernel, "%.3g", worst_kernel);
  std::printf("  %d frames, per-channel fog against each channel's grey fog: worst |rgb - grey| / max(1, |grey|) "
              "scalar<double> %.3g, scalar<float> %.3g, kernel %s (%d of %d kernels the per-channel light "
              "variant)\n  lights in the per-channel fog: %d darker and %d non-finite channels, most added %.3g\n",
              frames, worst_double, worst_float, kernel, rgb_variants, frames, darker, nonfinite, most_added);
  EXPECT_LE(worst_double, 1e-12);
  EXPECT_LE(worst_float, 2e-6);
  EXPECT_LE(worst_kernel, 2e-6);
  if (runtime() != nullptr) {
    EXPECT_EQ(rgb_variants, frames);
  }
  EXPECT_EQ(darker, 0);
  EXPECT_EQ(nonfinite, 0);
  EXPECT_GT(most_added, 0.01);
}

}  // namespace
}  // namespace fogcl::test
