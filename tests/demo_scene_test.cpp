// The built-in demo scene: orientation, depth against independent ray casts, Z conventions,
// resolution independence, sizes and color formats.
#include "fogcl/demo_scene.h"

#include <cmath>
#include <optional>

#include <glm/ext/matrix_transform.hpp>
#include <glm/gtc/matrix_inverse.hpp>
#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>
#include <gtest/gtest.h>

#include "fogcl/error.h"

namespace fogcl {
namespace {

constexpr double kPi = 3.14159265358979323846;

double linear01(const CameraParams& p, float raw) {
  return 1.0 / (double(p.zbuffer_params.x) * double(raw) + double(p.zbuffer_params.y));
}
double eye_depth(const DemoFrame& f, int x, int y) {
  return linear01(f.params, f.depth.at(x, y)) * double(f.params.far_plane());
}
float sky_raw(const DemoFrame& f) { return f.params.reversed_z ? 0.0f : 1.0f; }
bool is_sky(const DemoFrame& f, int x, int y) { return f.depth.at(x, y) == sky_raw(f); }

// An independent camera model: GLM's left-handed look-at (Unity's view space: +x right, +y up,
// +z forward) and the pinhole of the vertical fov; not the frustum corners the scene uses.
struct Ray {
  glm::dvec3 origin;
  glm::dvec3 dir;  // view z of dir is 1, so the hit parameter is the eye depth
};
glm::dmat4 view_matrix(const DemoView& view) {
  return glm::lookAtLH(glm::dvec3(view.eye), glm::dvec3(view.target), glm::dvec3(0, 1, 0));
}
Ray pixel_ray(const DemoFrame& f, const DemoView& view, int x, int y) {
  const int w = f.color.width(), h = f.color.height();
  const double u = (x + 0.5) / w, v = 1.0 - (y + 0.5) / h;
  const double th = std::tan(double(f.camera.fov_y_deg) * kPi / 360.0);
  const double aspect = double(w) / double(h);
  const glm::dvec4 d_view(th * aspect * (2 * u - 1), th * (2 * v - 1), 1.0, 0.0);
  const glm::dmat4 to_world = glm::inverse(view_matrix(view));
  return {glm::dvec3(view.eye), glm::dvec3(to_world * d_view)};
}
// uv of a world point seen by the camera.
glm::dvec2 project(const DemoFrame& f, const DemoView& view, glm::dvec3 world) {
  const glm::dvec4 pv = view_matrix(view) * glm::dvec4(world, 1.0);
  const double th = std::tan(double(f.camera.fov_y_deg) * kPi / 360.0);
  const double aspect = double(f.color.width()) / double(f.color.height());
  return {0.5 + 0.5 * pv.x / (pv.z * th * aspect), 0.5 + 0.5 * pv.y / (pv.z * th)};
}
glm::ivec2 pixel_at(const DemoFrame& f, glm::dvec2 uv) {
  return {int(std::floor(uv.x * f.color.width())), int(std::floor((1.0 - uv.y) * f.color.height()))};
}

std::optional<double> hit_ground(const Ray& r) {
  if (!(r.dir.y < 0.0)) return std::nullopt;
  return -r.origin.y / r.dir.y;
}
std::optional<double> hit_sphere(const Ray& r, glm::dvec3 c, double radius) {
  const glm::dvec3 oc = r.origin - c;
  const double a = glm::dot(r.dir, r.dir), b = glm::dot(oc, r.dir);
  const double disc = b * b - a * (glm::dot(oc, oc) - radius * radius);
  if (disc < 0.0) return std::nullopt;
  return (-b - std::sqrt(disc)) / a;
}

// Two documented spheres of the scene (see demo_scene.h), B on world +x, A on world -x.
const glm::dvec3 kSphereB(2.2, 1.0, -0.5);
constexpr double kSphereBRadius = 1.0;
const glm::dvec3 kSphereA(-0.9, 0.5, -3.5);
constexpr double kSphereARadius = 0.5;

// The view looks back along -z, pitched down: only ground and sky are visible (every sphere has
// z >= -4 and lies behind the eye).
const DemoView kGroundOnlyView{{0.0f, 2.0f, -6.0f}, {0.0f, 0.0f, -16.0f}};

TEST(DemoScene, GroundAtTheBottomSkyAtTheTop) {
  for (bool reversed : {false, true}) {
    PerspectiveCamera cam;
    cam.reversed_z = reversed;
    const DemoFrame f = render_demo_scene(160, 90, cam);
    const int cx = 80;
    EXPECT_FALSE(is_sky(f, cx, 89)) << "reversed " << reversed;
    const double z_bottom = eye_depth(f, cx, 89);
    EXPECT_GT(z_bottom, double(cam.near_plane));
    EXPECT_LT(z_bottom, 10.0);
    EXPECT_TRUE(is_sky(f, cx, 0));
    EXPECT_GT(linear01(f.params, f.depth.at(cx, 0)), 0.9999);
    // The sky is bluish and not black.
    const glm::vec4 top = f.color.pixel(cx, 0);
    EXPECT_GT(top.b, top.r);
    EXPECT_GT(top.r, 0.1f);
  }
}

TEST(DemoScene, GroundDepthMatchesPlaneIntersection) {
  for (bool reversed : {false, true}) {
    PerspectiveCamera cam;
    cam.reversed_z = reversed;
    const int w = 96, h = 64;
    const DemoFrame f = render_demo_scene(w, h, cam, kGroundOnlyView);
    // Bottom half: rays at least ~11 degrees below the horizon, all hit the ground near by.
    int checked = 0;
    for (int y = h / 2; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const auto z = hit_ground(pixel_ray(f, kGroundOnlyView, x, y));
        ASSERT_TRUE(z.has_value());
        ASSERT_FALSE(is_sky(f, x, y)) << x << "," << y;
        EXPECT_NEAR(eye_depth(f, x, y), *z, 1e-4 * *z) << x << "," << y << " reversed " << reversed;
        ++checked;
      }
    EXPECT_EQ(checked, w * h / 2);
    // Whole image: sky exactly where the ray misses the ground or meets it beyond the far plane
    // (pixels within 1e-6 of the far plane are not judged).
    const double far = double(cam.far_plane);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const auto z = hit_ground(pixel_ray(f, kGroundOnlyView, x, y));
        if (z && std::fabs(*z - far) < 1e-6 * far) continue;
        EXPECT_EQ(is_sky(f, x, y), !z || *z > far) << x << "," << y;
      }
  }
}

TEST(DemoScene, DepthOfKnownPixelsInTheDefaultView) {
  // Bottom-centre (ground) and the projected centre of sphere B.
  const DemoView view;
  const DemoFrame f = render_demo_scene(320, 180);
  const auto zg = hit_ground(pixel_ray(f, view, 160, 179));
  ASSERT_TRUE(zg.has_value());
  EXPECT_NEAR(eye_depth(f, 160, 179), *zg, 1e-4 * *zg);

  const glm::ivec2 pb = pixel_at(f, project(f, view, kSphereB));
  const auto zb = hit_sphere(pixel_ray(f, view, pb.x, pb.y), kSphereB, kSphereBRadius);
  ASSERT_TRUE(zb.has_value());
  EXPECT_NEAR(eye_depth(f, pb.x, pb.y), *zb, 1e-4 * *zb);
}

TEST(DemoScene, ConventionalAndReversedZAgree) {
  PerspectiveCamera conv, rev;
  rev.reversed_z = true;
  const int w = 240, h = 135;
  const DemoFrame a = render_demo_scene(w, h, conv);
  const DemoFrame b = render_demo_scene(w, h, rev);
  EXPECT_FALSE(a.params.reversed_z);
  EXPECT_TRUE(b.params.reversed_z);
  int non_sky = 0, far_ground = 0;
  double worst = 0.0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      // Same colors: the Z convention changes only the depth encoding.
      ASSERT_EQ(a.color.pixel(x, y), b.color.pixel(x, y));
      ASSERT_EQ(is_sky(a, x, y), is_sky(b, x, y)) << x << "," << y;
      const double la = linear01(a.params, a.depth.at(x, y));
      const double lb = linear01(b.params, b.depth.at(x, y));
      // Catlike's sky test agrees too (away from its 0.9999 threshold).
      if (std::fabs(lb - 0.9999) > 1e-5) {
        EXPECT_EQ(la > 0.9999, lb > 0.9999) << x << "," << y;
      }
      if (is_sky(a, x, y)) continue;
      ++non_sky;
      // 1e-5 relative, plus what rounding conventional raw depth to float costs: near raw = 1
      // a float step of raw moves Linear01 by |zb.x| * step * Linear01^2.
      const float raw = a.depth.at(x, y);
      const double step = double(std::nextafter(raw, 2.0f)) - double(raw);
      const double quant = 0.5 * std::fabs(double(a.params.zbuffer_params.x)) * step * la;
      if (quant > 1e-5) ++far_ground;
      const double rel = std::fabs(la - lb) / lb;
      worst = std::max(worst, rel);
      EXPECT_LE(rel, 1e-5 + quant * 1.01) << x << "," << y << " z " << lb * 1000.0;
    }
  EXPECT_GT(non_sky, w * h / 3);
  RecordProperty("worst_relative_linear01_difference", std::to_string(worst));
  RecordProperty("pixels_beyond_1e-5_float_depth_resolution", std::to_string(far_ground));
}

TEST(DemoScene, ResolutionDoesNotMoveTheScene) {
  // 64x36 pixel centres coincide with the centres of 320x180 pixels (5x + 2, 5y + 2): the same
  // rays, so bit-identical color and depth there.
  const DemoFrame lo = render_demo_scene(64, 36);
  const DemoFrame hi = render_demo_scene(320, 180);
  for (int y = 0; y < 36; ++y)
    for (int x = 0; x < 64; ++x) {
      ASSERT_EQ(lo.depth.at(x, y), hi.depth.at(5 * x + 2, 5 * y + 2)) << x << "," << y;
      ASSERT_EQ(lo.color.pixel(x, y), hi.color.pixel(5 * x + 2, 5 * y + 2)) << x << "," << y;
    }
  // Sphere B sits at the same uv at both sizes (and at a third, unrelated one).
  const DemoView view;
  for (const DemoFrame* f : {&lo, &hi}) {
    const glm::dvec2 uv = project(*f, view, kSphereB);
    const glm::ivec2 p = pixel_at(*f, uv);
    const auto z = hit_sphere(pixel_ray(*f, view, p.x, p.y), kSphereB, kSphereBRadius);
    ASSERT_TRUE(z.has_value());
    EXPECT_NEAR(eye_depth(*f, p.x, p.y), *z, 1e-4 * *z);
  }
  const DemoFrame odd = render_demo_scene(101, 57);  // aspect 1.77, close to 16:9
  const glm::ivec2 p = pixel_at(odd, project(odd, view, kSphereB));
  const auto z = hit_sphere(pixel_ray(odd, view, p.x, p.y), kSphereB, kSphereBRadius);
  ASSERT_TRUE(z.has_value());
  EXPECT_NEAR(eye_depth(odd, p.x, p.y), *z, 1e-4 * *z);
}

TEST(DemoScene, WorldPlusXIsImageRightWhenLookingAlongPlusZ) {
  const DemoView view;  // looks along +z (slightly down)
  ASSERT_GT(view.target.z, view.eye.z);
  const int w = 320, h = 180;
  const DemoFrame f = render_demo_scene(w, h, {}, view);
  // Sphere B (x = +2.2) in the right half, sphere A (x = -0.9) in the left half: the pixel at each
  // projected centre has the depth of that sphere, and the mirrored pixel does not.
  struct Case {
    glm::dvec3 c;
    double r;
    bool right;
  };
  for (const Case& s : {Case{kSphereB, kSphereBRadius, true}, Case{kSphereA, kSphereARadius, false}}) {
    const glm::dvec2 uv = project(f, view, s.c);
    EXPECT_EQ(uv.x > 0.5, s.right);
    const glm::ivec2 p = pixel_at(f, uv);
    const auto z = hit_sphere(pixel_ray(f, view, p.x, p.y), s.c, s.r);
    ASSERT_TRUE(z.has_value());
    EXPECT_NEAR(eye_depth(f, p.x, p.y), *z, 1e-4 * *z);
    const int mx = w - 1 - p.x;
    EXPECT_FALSE(std::fabs(eye_depth(f, mx, p.y) - *z) < 1e-3 * *z) << "mirrored pixel " << mx;
  }
  // Looking back along -z from the far side, sphere B (world +x) is on the image's left.
  const DemoView back{{0.0f, 1.0f, 10.0f}, {0.0f, 1.0f, 0.0f}};
  const DemoFrame g = render_demo_scene(w, h, {}, back);
  const glm::dvec2 uv = project(g, back, kSphereB);
  EXPECT_LT(uv.x, 0.5);
  const glm::ivec2 p = pixel_at(g, uv);
  const auto z = hit_sphere(pixel_ray(g, back, p.x, p.y), kSphereB, kSphereBRadius);
  ASSERT_TRUE(z.has_value());
  EXPECT_NEAR(eye_depth(g, p.x, p.y), *z, 1e-4 * *z);
}

TEST(DemoScene, AspectIsWidthOverHeight) {
  PerspectiveCamera cam;
  cam.aspect = 3.0f;  // ignored
  const DemoFrame f = render_demo_scene(40, 30, cam);
  EXPECT_EQ(f.camera.aspect, 40.0f / 30.0f);
  const CameraParams expected = make_camera_params(f.camera);
  EXPECT_EQ(f.params.zbuffer_params, expected.zbuffer_params);
  EXPECT_EQ(f.params.projection_params, expected.projection_params);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(f.params.frustum_corners[i], expected.frustum_corners[i]);
  EXPECT_EQ(f.color.width(), 40);
  EXPECT_EQ(f.color.height(), 30);
  EXPECT_EQ(f.depth.width(), 40);
  EXPECT_EQ(f.depth.height(), 30);
  EXPECT_EQ(render_demo_scene(7, 5).camera.aspect, 7.0f / 5.0f);
}

TEST(DemoScene, TinySizesWork) {
  const DemoFrame one = render_demo_scene(1, 1);
  const DemoFrame odd = render_demo_scene(7, 5);
  // The centre pixel's ray is the view direction whatever the aspect: it meets the ground.
  EXPECT_FALSE(is_sky(one, 0, 0));
  EXPECT_EQ(one.depth.at(0, 0), odd.depth.at(3, 2));
  EXPECT_EQ(one.color.pixel(0, 0), odd.color.pixel(3, 2));
  const DemoView view;
  const auto z = hit_ground(pixel_ray(one, view, 0, 0));
  ASSERT_TRUE(z.has_value());
  EXPECT_NEAR(eye_depth(one, 0, 0), *z, 1e-4 * *z);
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 7; ++x) {
      const glm::vec4 c = odd.color.pixel(x, y);
      for (int k = 0; k < 3; ++k) {
        EXPECT_TRUE(std::isfinite(c[k]));
        EXPECT_GE(c[k], 0.0f);
        EXPECT_LE(c[k], 1.5f);
      }
      EXPECT_EQ(c.a, 1.0f);
      EXPECT_GE(odd.depth.at(x, y), 0.0f);
      EXPECT_LE(odd.depth.at(x, y), 1.0f);
    }
}

TEST(DemoScene, ColorsAreSaneEverywhere) {
  const DemoFrame f = render_demo_scene(192, 108);
  double lo = 1e9, hi = -1e9;
  for (int y = 0; y < 108; ++y)
    for (int x = 0; x < 192; ++x) {
      const glm::vec4 c = f.color.pixel(x, y);
      ASSERT_EQ(c.a, 1.0f);
      for (int k = 0; k < 3; ++k) {
        ASSERT_TRUE(std::isfinite(c[k]));
        lo = std::min(lo, double(c[k]));
        hi = std::max(hi, double(c[k]));
      }
    }
  EXPECT_GT(lo, 0.0);  // ambient light everywhere
  EXPECT_LE(hi, 1.5);
}

TEST(DemoScene, HalfFloatColorMatchesFloat) {
  const DemoFrame a = render_demo_scene(96, 54, {}, {}, ColorFormat::rgba32f);
  const DemoFrame b = render_demo_scene(96, 54, {}, {}, ColorFormat::rgba16f);
  EXPECT_EQ(b.color.format(), ColorFormat::rgba16f);
  for (int y = 0; y < 54; ++y)
    for (int x = 0; x < 96; ++x) {
      ASSERT_EQ(a.depth.at(x, y), b.depth.at(x, y));
      const glm::vec4 ca = a.color.pixel(x, y), cb = b.color.pixel(x, y);
      for (int k = 0; k < 4; ++k)
        ASSERT_NEAR(cb[k], ca[k], std::ldexp(std::fabs(ca[k]), -11)) << x << "," << y << " " << k;
    }
}

TEST(DemoScene, RejectsBadInput) {
  EXPECT_THROW(render_demo_scene(0, 10), Error);
  EXPECT_THROW(render_demo_scene(10, -1), Error);
  PerspectiveCamera bad;
  bad.fov_y_deg = 0.0f;
  EXPECT_THROW(render_demo_scene(8, 8, bad), Error);
  bad = {};
  bad.far_plane = bad.near_plane;
  EXPECT_THROW(render_demo_scene(8, 8, bad), Error);
  EXPECT_THROW(render_demo_scene(8, 8, {}, DemoView{{1, 2, 3}, {1, 2, 3}}), Error);
  EXPECT_THROW(render_demo_scene(8, 8, {}, DemoView{{0, 2, 0}, {0, 0, 0}}), Error);
  EXPECT_THROW(render_demo_scene(8, 8, {}, DemoView{{2.2f, 1.0f, -0.5f}, {0, 1, 10}}), Error);
}

}  // namespace
}  // namespace fogcl
