// The physical integrator against closed forms (docs/volumetric.md §The march): a sphere of constant
// extinction, noise and fades off, lit by ambient light only, has T = e^(-sigma_t L) over the
// chord L the depth buffer leaves of it, and in-scattered I = albedo * ambient * (1 - T), for any
// step count. Checked on the scalar<double> path and on the OpenCL kernel, camera outside, inside,
// the sphere half behind an occluder, behind the far plane, partly off screen, orthographic.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "fogcl/depth_kinds.h"
#include "volume_support.h"

namespace fogcl::test {
namespace {

struct Case {
  const char* name;
  glm::vec3 center;
  float radius;
  float wall_depth;     // eye depth of the occluder on the right half of the frame (+inf: sky)
  bool orthographic = false;
};

constexpr int kW = 64, kH = 40;
const glm::dvec3 kAmbient{0.3, 0.2, 0.1};
const glm::dvec3 kAlbedo{0.9, 0.8, 0.7};
const glm::dvec3 kScene{0.2, 0.4, 0.6};
constexpr double kSigma = 0.35;

struct AnalyticFrame {
  ColorImage color;
  DepthImage depth;
  CameraParams params;
  VolumeScene scene;
};

AnalyticFrame make_frame(const Case& c) {
  AnalyticFrame f;
  f.color = uniform_image(kW, kH, ColorFormat::rgba32f, glm::vec4(glm::vec3(kScene), 1.0f));
  f.depth = DepthImage(kW, kH);
  if (c.orthographic) {
    OrthographicCamera cam;
    cam.ortho_size = 4.0f;
    cam.aspect = float(kW) / kH;
    cam.near_plane = 0.5f;
    cam.far_plane = 60.0f;
    f.params = make_camera_params(cam);
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x)
        f.depth.at(x, y) = x >= kW / 2 && std::isfinite(c.wall_depth)
                               ? float((double(c.wall_depth) - cam.near_plane) / (cam.far_plane - cam.near_plane))
                               : 1.0f;
  } else {
    PerspectiveCamera cam;
    cam.fov_y_deg = 60.0f;
    cam.aspect = float(kW) / kH;
    cam.near_plane = 0.3f;
    cam.far_plane = 60.0f;
    f.params = make_camera_params(cam);
    DepthImage eye(kW, kH, INFINITY);
    for (int y = 0; y < kH; ++y)
      for (int x = kW / 2; x < kW; ++x) eye.at(x, y) = c.wall_depth;
    to_raw_depth(eye, DepthKind::eye, f.params);
    f.depth = eye;
  }
  FogVolume v;
  v.center = c.center;
  v.radius = c.radius;
  v.density = float(kSigma);
  v.noise = false;
  v.fade_edge = v.fade_y = v.proximity_fade = 0.0f;
  v.max_y = 1e6f;
  v.albedo = glm::vec3(kAlbedo);
  v.ambient = glm::vec3(kAmbient);
  f.scene.volumes = {v};
  f.scene.light.color = glm::vec3(0.0f);  // ambient light only
  return f;
}

// The closed form at pixel (x, y), in double, computed here from the definitions (docs: rays
// start on the near plane; the occluder lies at (eye depth - near) |c| / c.z along the ray).
glm::dvec4 expected(const AnalyticFrame& f, const Case& c, int x, int y) {
  const double u = (x + 0.5) / kW, v = 1.0 - (y + 0.5) / kH;
  const auto& k = f.params.frustum_corners;
  glm::dvec3 corner;
  for (int i = 0; i < 3; ++i) {
    const double left = k[kBottomLeft][i] + (double(k[kTopLeft][i]) - k[kBottomLeft][i]) * v;
    const double right = k[kBottomRight][i] + (double(k[kTopRight][i]) - k[kBottomRight][i]) * v;
    corner[i] = left + (right - left) * u;
  }
  const double n = f.params.near_plane();
  glm::dvec3 origin, dir;
  double t_scene = INFINITY;
  const bool wall = x >= kW / 2 && std::isfinite(c.wall_depth);
  if (c.orthographic) {
    origin = {corner.x, corner.y, n};
    dir = {0, 0, 1};
    if (wall) t_scene = double(c.wall_depth) - n;
  } else {
    origin = corner * (n / corner.z);
    dir = glm::normalize(corner);
    if (wall) t_scene = (double(c.wall_depth) - n) * glm::length(corner) / corner.z;
  }
  const glm::dvec3 oc = origin - glm::dvec3(c.center);
  const double b = glm::dot(oc, dir), cc = glm::dot(oc, oc) - double(c.radius) * c.radius;
  const double disc = b * b - cc;
  double chord = 0;
  if (disc > 0) {
    const double t0 = std::max(-b - std::sqrt(disc), 0.0), t1 = std::min(-b + std::sqrt(disc), t_scene);
    chord = std::max(t1 - t0, 0.0);
  }
  const double transmittance = std::exp(-kSigma * chord);
  const glm::dvec3 rgb = kAlbedo * kAmbient * (1.0 - transmittance) + kScene * transmittance;
  return {rgb, transmittance};
}

const Case kCases[] = {
    {"camera-outside", {0.5f, 0.3f, 8.0f}, 2.5f, INFINITY},
    {"camera-inside", {0.0f, 0.0f, 1.0f}, 4.0f, INFINITY},
    {"half-behind-occluder", {0.0f, 0.0f, 10.0f}, 3.0f, 10.0f},
    {"behind-far-plane", {0.0f, 0.0f, 62.0f}, 4.0f, 50.0f},  // sky sees it, the wall hides it
    {"partly-off-screen", {6.0f, 2.0f, 9.0f}, 3.0f, 12.0f},
    {"orthographic", {1.0f, -0.5f, 6.0f}, 2.5f, 7.0f, true},
};

class VolumeAnalytic : public ::testing::TestWithParam<std::tuple<int, int>> {};

TEST_P(VolumeAnalytic, PhysicalMatchesClosedForm) {
  const Case& c = kCases[std::get<0>(GetParam())];
  const int steps = std::get<1>(GetParam());
  const AnalyticFrame f = make_frame(c);
  VolumeSettings settings;
  settings.integrator = VolumeIntegrator::physical;
  settings.resolution_divisor = 1;
  settings.steps = steps;
  settings.jitter = false;
  const VolumeResult<double> ref = volumes_scalar<double>(f.color, f.depth, f.params, f.scene, settings);
  ColorImage kernel_out;
  const bool device = runtime() != nullptr;
  if (device) VolumePass(*runtime()).apply(f.color, f.depth, kernel_out, f.params, f.scene, settings);
  double worst_ref = 0, worst_kernel = 0, worst_t = 0;
  int chords = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const glm::dvec4 e = expected(f, c, x, y);
      if (e.w < 1.0) ++chords;
      const std::size_t i = std::size_t(y) * kW + x;
      worst_t = std::max(worst_t, std::fabs((1.0 - ref.low[4 * i + 3]) - e.w) / e.w);
      for (int k = 0; k < 3; ++k) {
        worst_ref = std::max(worst_ref, std::fabs(ref.rgba[4 * i + k] - e[k]) / e[k]);
        if (device) worst_kernel = std::max(worst_kernel, std::fabs(double(kernel_out.pixel(x, y)[k]) - e[k]) / e[k]);
      }
    }
  std::printf("  %s, %d steps: %d pixels with a chord; worst relative error: reference %.3g (T %.3g), kernel %.3g%s\n",
              c.name, steps, chords, worst_ref, worst_t, worst_kernel, device ? "" : " (no device)");
  EXPECT_GT(chords, 0);
  EXPECT_LE(worst_ref, 1e-5);
  EXPECT_LE(worst_t, 1e-5);
  // The float kernel: its rays and chords are float geometry, and a ray grazing the sphere turns
  // an ulp of the perpendicular distance into ~1e-5 of the chord.
  if (device) {
    EXPECT_LE(worst_kernel, 1e-4);
  }
}

INSTANTIATE_TEST_SUITE_P(Cases, VolumeAnalytic,
                         ::testing::Combine(::testing::Range(0, int(std::size(kCases))), ::testing::Values(1, 8, 64)),
                         [](const auto& info) {
                           std::string n = kCases[std::get<0>(info.param)].name;
                           std::replace(n.begin(), n.end(), '-', '_');
                           return n + "_" + std::to_string(std::get<1>(info.param)) + "steps";
                         });

}  // namespace
}  // namespace fogcl::test
