// The built-in test scene (Catlike Coding "Rendering 14: Fog"): gray-white spheres on an infinite
// ground plane under a sky gradient, ray cast analytically in double, one ray per pixel centre
// (no anti-aliasing: the depth of a pixel is the depth of the surface its colour comes from).
#include "fogcl/demo_scene.h"

#include <algorithm>
#include <array>
#include <cstddef>
#include <cmath>
#include <limits>
#include <string>

#include "fogcl/error.h"

namespace fogcl {

namespace {

struct V3 {
  double x = 0, y = 0, z = 0;
};
V3 operator+(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
V3 operator-(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
V3 operator*(V3 a, double s) { return {a.x * s, a.y * s, a.z * s}; }
double dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
V3 cross(V3 a, V3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
double length(V3 a) { return std::sqrt(dot(a, a)); }
V3 normalize(V3 a) { return a * (1.0 / length(a)); }
V3 to_v3(const glm::vec3& v) { return {double(v.x), double(v.y), double(v.z)}; }

struct Sphere {
  V3 centre;
  double radius;
  double albedo;
};

// The scene, in world units (Unity's world: left-handed, +x right, +y up, +z forward). Every
// sphere rests on the ground; distances of the centres from the default eye (0, 1.6, -6): about
// 2.9, 6.0, 13.5, 25, 33, 48 and 71.
constexpr int kSphereCount = 7;
const std::array<Sphere, kSphereCount> kSpheres{{
    {{-0.9, 0.5, -3.5}, 0.5, 0.80},
    {{2.2, 1.0, -0.5}, 1.0, 0.82},
    {{-3.8, 1.5, 7.0}, 1.5, 0.78},
    {{-12.0, 2.0, 16.0}, 2.0, 0.80},
    {{-3.0, 3.0, 27.0}, 3.0, 0.82},
    {{5.0, 4.0, 42.0}, 4.0, 0.78},
    {{34.0, 5.0, 56.0}, 5.0, 0.80},
}};

constexpr double kGroundAlbedo = 0.80;      // checker squares: 0.80 and 0.80 - kCheckerContrast
constexpr double kCheckerContrast = 0.08;
constexpr double kCheckerSize = 2.0;        // [world units]
constexpr double kFadeAngle = 1e-3;         // [rad]
const V3 kSunColor{1.00, 0.96, 0.90};
const V3 kAmbient{0.22, 0.25, 0.30};
const V3 kSkyHorizon{0.85, 0.93, 1.10};
const V3 kSkyZenith{0.30, 0.50, 0.90};

// First hit of the ray o + t d (t > t_min) with a sphere; returns +inf when there is none.
double hit_sphere(const Sphere& s, V3 o, V3 d, double t_min) {
  const V3 oc = o - s.centre;
  const double a = dot(d, d);
  const double b = dot(oc, d);
  const double c = dot(oc, oc) - s.radius * s.radius;
  const double disc = b * b - a * c;
  if (disc < 0.0) return std::numeric_limits<double>::infinity();
  const double sq = std::sqrt(disc);
  // Stable roots: q = -(b + sign(b) sq); t0 = q / a, t1 = c / q.
  const double q = b > 0.0 ? -(b + sq) : -(b - sq);
  double t0 = q / a, t1 = q != 0.0 ? c / q : t0;
  if (t0 > t1) std::swap(t0, t1);
  if (t0 > t_min) return t0;
  if (t1 > t_min) return t1;
  return std::numeric_limits<double>::infinity();
}

bool in_shadow(V3 p, V3 to_light) {
  for (const Sphere& s : kSpheres)
    if (std::isfinite(hit_sphere(s, p, to_light, 1e-6))) return true;
  return false;
}

// The light, as the shading below and the shadow map use it.
const V3 kToLight{0.35, 0.80, -0.50};

// The scene's default sun, or the caller's direction (checked: finite, not vertical, as the
// shadow map's light camera needs a horizontal right axis).
V3 sun_direction(const std::optional<glm::vec3>& to_light) {
  if (!to_light) return normalize(kToLight);
  const V3 d = to_v3(*to_light);
  const double len = length(d);
  if (!(std::isfinite(len) && len > 0.0))
    throw Error("demo sun direction must be finite and non-zero");
  const V3 u = d * (1.0 / len);
  if (!(std::fabs(u.y) < 0.999)) throw Error("demo sun direction must not be vertical (|y| / length >= 0.999)");
  return u;
}

V3 sky(V3 dir_unit) {
  const double s = std::sqrt(std::clamp(dir_unit.y, 0.0, 1.0));
  return kSkyHorizon * (1.0 - s) + kSkyZenith * s;
}

}  // namespace

DemoFrame render_demo_scene(int width, int height, PerspectiveCamera camera,
                            const DemoView& view, ColorFormat format, const std::optional<glm::vec3>& to_light_dir) {
  if (width < 1 || height < 1)
    throw Error("demo scene size must be at least 1x1 (got " + std::to_string(width) + "x" +
                std::to_string(height) + ")");
  camera.aspect = float(width) / float(height);
  DemoFrame frame;
  frame.params = make_camera_params(camera);  // validates the camera
  frame.camera = camera;
  frame.color = ColorImage(width, height, format);

  const CameraParams& p = frame.params;
  const double far = double(p.far_plane());
  const double near = double(p.near_plane());
  const double zb_x = double(p.zbuffer_params.x), zb_y = double(p.zbuffer_params.y);
  const float sky_raw = p.reversed_z ? 0.0f : 1.0f;
  const float near_raw = p.reversed_z ? 1.0f : 0.0f;
  frame.depth = DepthImage(width, height, sky_raw);

  // Camera basis (left-handed like Unity's view space): view +z = forward, +x = right, +y = up.
  const V3 eye = to_v3(view.eye);
  const V3 to_target = to_v3(view.target) - eye;
  if (!(length(to_target) > 0.0) || !std::isfinite(length(to_target)))
    throw Error("demo view target must differ from the eye and be finite");
  const V3 forward = normalize(to_target);
  const V3 world_up{0.0, 1.0, 0.0};
  const V3 right_raw = cross(world_up, forward);
  if (!(length(right_raw) > 1e-9))
    throw Error("demo view must not look straight up or down (forward is parallel to +y)");
  const V3 right = normalize(right_raw);
  const V3 up = cross(forward, right);

  std::array<V3, 4> corner;
  for (int i = 0; i < 4; ++i) corner[i] = to_v3(p.frustum_corners[i]) * (1.0 / far);

  // Per-sphere terms of the primary rays, which all start at the eye.
  std::array<V3, kSphereCount> eye_to_centre;
  std::array<double, kSphereCount> eye_c;
  bool eye_outside = true;
  for (int i = 0; i < kSphereCount; ++i) {
    eye_to_centre[i] = kSpheres[i].centre - eye;
    eye_c[i] = dot(eye_to_centre[i], eye_to_centre[i]) - kSpheres[i].radius * kSpheres[i].radius;
    eye_outside = eye_outside && eye_c[i] > 0.0;
  }
  if (!eye_outside) throw Error("demo view eye must lie outside the scene's spheres");

  const V3 to_light = sun_direction(to_light_dir);

  float* const rgba32 = format == ColorFormat::rgba32f ? frame.color.rgba32f() : nullptr;
  for (int y = 0; y < height; ++y) {
    const double v = 1.0 - (double(y) + 0.5) / double(height);
    for (int x = 0; x < width; ++x) {
      const double u = (double(x) + 0.5) / double(width);
      // Bilinear interpolation of the corners (index u + 2v); view z is exactly 1.
      const V3 bottom = corner[kBottomLeft] * (1.0 - u) + corner[kBottomRight] * u;
      const V3 top = corner[kTopLeft] * (1.0 - u) + corner[kTopRight] * u;
      const V3 ray_view = bottom * (1.0 - v) + top * v;
      const V3 dir = right * ray_view.x + up * ray_view.y + forward * ray_view.z;
      const V3 dir_unit = normalize(dir);

      // Nearest hit; t is the view depth z_eye because the ray's view z is 1.
      double t = std::numeric_limits<double>::infinity();
      int hit = -1;  // -1: none, 0..: sphere, kSphereCount: ground
      const double a = dot(dir, dir);
      for (int i = 0; i < kSphereCount; ++i) {
        // Nearest root of a t^2 + 2 b t + c (the eye is outside every sphere: c > 0).
        const double b = dot(eye_to_centre[i], dir) * -1.0;
        if (b >= 0.0) continue;  // the sphere is behind the eye
        const double disc = b * b - a * eye_c[i];
        if (disc < 0.0) continue;
        const double ti = eye_c[i] / (-b + std::sqrt(disc));  // stable form of (-b - sqrt) / a
        if (ti < t) t = ti, hit = i;
      }
      if (dir.y < 0.0 && eye.y > 0.0) {
        const double tg = -eye.y / dir.y;
        if (tg < t) t = tg, hit = kSphereCount;
      }

      V3 rgb;
      if (hit < 0 || !(t <= far)) {
        // Sky, and everything beyond the far plane: keeps the sky depth.
        rgb = sky(dir_unit);
      } else {
        const V3 pos = eye + dir * t;
        V3 normal;
        double albedo;
        if (hit == kSphereCount) {
          normal = {0.0, 1.0, 0.0};
          const long cx = long(std::floor(pos.x / kCheckerSize));
          const long cz = long(std::floor(pos.z / kCheckerSize));
          // Ground footprint of a 1 mrad pixel (about 1080p at 60 degrees; grows at grazing
          // angles); the checker fades out before a square is smaller than two such pixels. A
          // fixed angle keeps the color a function of the ray alone, whatever the resolution.
          const double footprint = t * length(dir) * kFadeAngle / std::max(-dir_unit.y, 1e-6);
          const double fade = std::clamp(1.0 - footprint / kCheckerSize * 2.0, 0.0, 1.0);
          albedo = kGroundAlbedo - (((cx + cz) & 1) != 0 ? kCheckerContrast * fade : 0.0) -
                   kCheckerContrast * 0.5 * (1.0 - fade);
        } else {
          normal = normalize(pos - kSpheres[hit].centre);
          albedo = kSpheres[hit].albedo;
        }
        const double n_dot_l = dot(normal, to_light);
        V3 light = kAmbient;
        if (n_dot_l > 0.0 && !in_shadow(pos + normal * 1e-7, to_light))
          light = light + kSunColor * n_dot_l;
        rgb = light * albedo;

        double raw;
        if (t < near) {
          raw = near_raw;
        } else {
          // Inverse of Linear01Depth with the float _ZBufferParams: 1/(x raw + y) = t / far.
          raw = std::clamp((far / t - zb_y) / zb_x, 0.0, 1.0);
        }
        frame.depth.at(x, y) = float(raw);
      }
      if (rgba32 != nullptr) {
        float* px = rgba32 + 4 * (std::size_t(y) * std::size_t(width) + std::size_t(x));
        px[0] = float(rgb.x), px[1] = float(rgb.y), px[2] = float(rgb.z), px[3] = 1.0f;
      } else {
        frame.color.set_pixel(x, y, glm::vec4(float(rgb.x), float(rgb.y), float(rgb.z), 1.0f));
      }
    }
  }
  return frame;
}

MainLight demo_light(const std::optional<glm::vec3>& to_light_dir) {
  MainLight light;
  const V3 d = sun_direction(to_light_dir);
  light.direction = glm::vec3(float(d.x), float(d.y), float(d.z));
  light.color = glm::vec3(float(kSunColor.x), float(kSunColor.y), float(kSunColor.z));
  return light;
}

MainLight demo_low_sun() { return demo_light(glm::vec3(-0.3f, 0.15f, 1.0f)); }

ShadowMap render_demo_shadow_map(int width, int height, const DemoShadowRegion& region,
                                 const std::optional<glm::vec3>& to_light_dir) {
  if (width < 1 || height < 1)
    throw Error("demo shadow map size must be at least 1x1 (got " + std::to_string(width) + "x" +
                std::to_string(height) + ")");
  // Light camera basis (left-handed, as a camera's): forward along the light's rays, right =
  // normalize(cross(+y, forward)), up = cross(forward, right). The light is never vertical here.
  const V3 forward = sun_direction(to_light_dir) * -1.0;
  const V3 right = normalize(cross(V3{0.0, 1.0, 0.0}, forward));
  const V3 up = cross(forward, right);

  // Fit the orthographic box to the region's corners in light view space.
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (int c = 0; c < 8; ++c) {
    const V3 p{(c & 1) ? region.max.x : region.min.x, (c & 2) ? region.max.y : region.min.y,
               (c & 4) ? region.max.z : region.min.z};
    const double l[3] = {dot(p, right), dot(p, up), dot(p, forward)};
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], l[k]), hi[k] = std::max(hi[k], l[k]);
  }
  for (int k = 0; k < 3; ++k) lo[k] -= 1.0, hi[k] += 1.0;  // the map's edges keep clear of the region
  const double sx = hi[0] - lo[0], sy = hi[1] - lo[1], sz = hi[2] - lo[2];
  if (!(sx > 0.0 && sy > 0.0 && sz > 0.0)) throw Error("demo shadow region must have a non-empty extent");

  // world -> light clip, row by row: clip.x = (2 l.x - (hi + lo)) / sx, clip.y likewise,
  // clip.z = (l.z - near) / sz, clip.w = 1.
  const double rows[4][4] = {
      {2.0 * right.x / sx, 2.0 * right.y / sx, 2.0 * right.z / sx, -(hi[0] + lo[0]) / sx},
      {2.0 * up.x / sy, 2.0 * up.y / sy, 2.0 * up.z / sy, -(hi[1] + lo[1]) / sy},
      {forward.x / sz, forward.y / sz, forward.z / sz, -lo[2] / sz},
      {0.0, 0.0, 0.0, 1.0}};
  ShadowMap map;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) map.params.world_to_light_clip[c][r] = float(rows[r][c]);  // GLM: [column][row]
  map.params.reversed_z = false;

  map.depth = DepthImage(width, height, 1.0f);
  for (int y = 0; y < height; ++y) {
    const double v = 1.0 - (double(y) + 0.5) / double(height);  // row 0 is the top: v = 1
    for (int x = 0; x < width; ++x) {
      const double u = (double(x) + 0.5) / double(width);
      // The texel's ray starts on the light's near plane and runs along forward (unit length,
      // so t is the distance past the near plane).
      const V3 o = right * (lo[0] + u * sx) + up * (lo[1] + v * sy) + forward * lo[2];
      double t = std::numeric_limits<double>::infinity();
      for (const Sphere& s : kSpheres) t = std::min(t, hit_sphere(s, o, forward, 0.0));
      // The ground (forward.y < 0); an origin below it sees only ground: depth 0.
      t = std::min(t, std::max(-o.y / forward.y, 0.0));
      if (t <= sz) map.depth.at(x, y) = float(t / sz);
    }
  }
  return map;
}

}  // namespace fogcl
