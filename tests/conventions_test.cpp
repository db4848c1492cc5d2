// docs/DESIGN.md §2 conventions, checked on the kernel (and the scalar path) with inputs whose answer
// is known independently: uv orientation and corner order, depth- vs distance-based distance,
// conventional vs reversed Z.
#include <cmath>
#include <cstdio>

#include "fogcl/demo_scene.h"
#include "test_support.h"

namespace fogcl::test {
namespace {

// Linear fog with start 0 and end E (> every distance) gives f = (E - d) / E, so a probe run
// (white color, black fog) returns d = E * (1 - f) per pixel.
constexpr float kProbeEnd = 4000.0f;

FogSettings distance_probe(FogMetric metric) {
  FogSettings s;
  s.mode = FogMode::linear;
  s.start = 0.0f;
  s.end = kProbeEnd;
  s.color = glm::vec3(0.0f);
  s.metric = metric;
  s.fog_skybox = true;
  return s;
}

// Distances per pixel measured through the kernel (or the scalar path when `scalar`).
std::vector<double> measured_distance(const DepthImage& depth, const CameraParams& cam,
                                      FogMetric metric, bool scalar) {
  ColorImage white(depth.width(), depth.height());
  white = white_like(white);
  ColorImage out;
  if (scalar)
    apply_fog_scalar(white, depth, out, cam, distance_probe(metric));
  else
    shared_pass().apply(white, depth, out, cam, distance_probe(metric));
  std::vector<double> d(depth.pixel_count());
  for (int y = 0; y < depth.height(); ++y)
    for (int x = 0; x < depth.width(); ++x)
      d[std::size_t(y) * depth.width() + x] = kProbeEnd * (1.0 - double(out.pixel(x, y).r));
  return d;
}

class Conventions : public ::testing::TestWithParam<bool /*scalar*/> {
 protected:
  void SetUp() override {
    if (!GetParam() && runtime() == nullptr) GTEST_SKIP() << "no OpenCL device: " << runtime_error();
  }
};

// One side of the frustum made 4x wider must lengthen the distances of the pixels on that side:
// checks both the corner order (u + 2v) and that v grows upwards.
TEST_P(Conventions, CornerOrderAndUvOrientation) {
  PerspectiveCamera camera;
  camera.aspect = 1.0f;
  const CameraParams base = make_camera_params(camera);
  DepthImage depth(2, 2, 0.5f);
  // Only valid cameras reach a pass (validate: the corners a rectangle on the far plane), so the
  // frustum is widened on one side at a time (off-centre); the two pixels on that side see
  // longer rays. Pixels: TL = 0, TR = 1, BL = 2, BR = 3 (row 0 = top).
  struct Side {
    const char* name;
    int axis;             // 0: x, 1: y
    Corner a, b;          // the side's corners
    std::size_t pa, pb;   // the side's pixels
  };
  const Side sides[] = {{"right", 0, kBottomRight, kTopRight, 3, 1},
                        {"left", 0, kBottomLeft, kTopLeft, 2, 0},
                        {"top", 1, kTopLeft, kTopRight, 0, 1},
                        {"bottom", 1, kBottomLeft, kBottomRight, 2, 3}};
  for (const Side& side : sides) {
    CameraParams cam = base;
    cam.non_square_pixels = true;  // the frustum is made off-centre and wider on purpose
    cam.frustum_corners[side.a][side.axis] *= 4.0f;
    cam.frustum_corners[side.b][side.axis] *= 4.0f;
    const std::vector<double> d = measured_distance(depth, cam, FogMetric::distance, GetParam());
    double ratio = 1e30;
    for (std::size_t i = 0; i < 4; ++i)
      if (i != side.pa && i != side.pb)
        for (std::size_t p : {side.pa, side.pb}) {
          EXPECT_GT(d[p], d[i] * 1.5) << side.name << " side: pixel " << p << " vs " << i;
          ratio = std::min(ratio, d[p] / d[i]);
        }
    std::printf("[ info     ] %s side widened: smallest distance ratio side/other %.3f (> 1.5)\n", side.name, ratio);
  }
}

// Depth-based d = Linear01Depth * far - near; distance-based at the image centre = that + near;
// at a corner pixel larger by 1/cos of the angle between its ray and the view axis.
TEST_P(Conventions, DepthAndDistanceMetrics) {
  for (bool reversed : {false, true}) {
    PerspectiveCamera camera;
    camera.fov_y_deg = 90.0f;
    camera.aspect = 1.0f;
    camera.reversed_z = reversed;
    const CameraParams cam = make_camera_params(camera);
    const int n = 101;  // odd: the centre pixel's ray is the view axis
    const double eye = 437.0;
    const double l01_target = eye / camera.far_plane;
    const float raw = float((1.0 / l01_target - cam.zbuffer_params.y) / cam.zbuffer_params.x);
    const double l01 = 1.0 / (double(cam.zbuffer_params.x) * raw + double(cam.zbuffer_params.y));
    DepthImage depth(n, n, raw);
    const std::vector<double> dd = measured_distance(depth, cam, FogMetric::depth, GetParam());
    const std::vector<double> dr = measured_distance(depth, cam, FogMetric::distance, GetParam());
    const double tol = 2e-3;  // probe resolution: kProbeEnd * (float f error ~ 3e-8) plus slack

    const double expect_depth = l01 * camera.far_plane - camera.near_plane;
    double worst_depth = 0;
    for (double d : dd) worst_depth = std::max(worst_depth, std::fabs(d - expect_depth));
    EXPECT_LE(worst_depth, tol);

    const std::size_t centre = std::size_t(n / 2) * n + n / 2;
    EXPECT_NEAR(dr[centre] - dd[centre], camera.near_plane, tol);

    // Corner pixel (0, 0): view ray (x, y, 1) with x, y = tan(fov/2) * (2u - 1), (2v - 1).
    const double t = std::tan(45.0 * M_PI / 180.0);
    const double x = t * (2 * (0.5 / n) - 1), y = t * (2 * (1 - 0.5 / n) - 1);
    const double inv_cos = std::sqrt(x * x + y * y + 1);
    const double corner_err = std::fabs(dr[0] - (dd[0] + camera.near_plane) * inv_cos);
    EXPECT_LE(corner_err, tol * inv_cos);
    std::printf("[ worst    ] %s %s: |depth d - (L01*far - near)| %.2e, centre distance - depth %.6f (near %.1f), corner 1/cos err %.2e\n",
                GetParam() ? "scalar" : "kernel", reversed ? "reversed-z" : "conventional-z",
                worst_depth, dr[centre] - dd[centre], camera.near_plane, corner_err);
  }
}

// The demo scene rendered in both Z conventions fogs to the same image. The only difference
// allowed is the one the float depth buffer itself makes: conventional Z quantises far depths
// (~1e-4 * z / far relative in Linear01Depth), which moves exp fog by at most density * dz.
TEST_P(Conventions, ConventionalAndReversedZAgree) {
  FogSettings s;
  s.mode = FogMode::exp;
  s.density = 0.035f;
  s.metric = FogMetric::distance;
  s.color = glm::vec3(0.6f, 0.7f, 0.8f);
  PerspectiveCamera conv, rev;
  rev.reversed_z = true;
  const DemoFrame a = render_demo_scene(320, 180, conv);
  const DemoFrame b = render_demo_scene(320, 180, rev);
  ColorImage oa, ob;
  if (GetParam()) {
    apply_fog_scalar(a.color, a.depth, oa, a.params, s);
    apply_fog_scalar(b.color, b.depth, ob, b.params, s);
  } else {
    shared_pass().apply(a.color, a.depth, oa, a.params, s);
    shared_pass().apply(b.color, b.depth, ob, b.params, s);
  }
  double worst = 0;
  for (int y = 0; y < 180; ++y)
    for (int x = 0; x < 320; ++x)
      for (int c = 0; c < 3; ++c) worst = std::max(worst, double(std::fabs(oa.pixel(x, y)[c] - ob.pixel(x, y)[c])));
  std::printf("[ worst    ] %s: |conventional - reversed| = %.2e\n", GetParam() ? "scalar" : "kernel", worst);
  EXPECT_LE(worst, 1e-5);
}

INSTANTIATE_TEST_SUITE_P(KernelAndScalar, Conventions, ::testing::Values(false, true),
                         [](const auto& info) { return info.param ? "scalar" : "kernel"; });

}  // namespace
}  // namespace fogcl::test
