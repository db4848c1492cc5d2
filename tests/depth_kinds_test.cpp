// Depth kinds (src/camera/depth_kinds.cpp): eye depth and radial distance to raw device depth, checked
// by going back with the formulas of docs/DESIGN.md §2 in double and with the camera's geometry.
#include <cmath>
#include <limits>

#include "fogcl/depth_kinds.h"
#include "fogcl/error.h"
#include "test_support.h"

namespace fogcl::test {
namespace {

PerspectiveCamera camera(bool reversed) {
  PerspectiveCamera c;
  c.fov_y_deg = 50.0f;
  c.aspect = 1.6f;
  c.near_plane = 0.3f;
  c.far_plane = 1000.0f;
  c.reversed_z = reversed;
  return c;
}

// LinearEyeDepth(raw) = 1 / (z raw + w), in double on the float constants.
double linear_eye_depth(double raw, const CameraParams& p) {
  return 1.0 / (double(p.zbuffer_params.z) * raw + double(p.zbuffer_params.w));
}

// |ray(u, v)| / view z of pixel (x, y) of a w x h frame, from the camera's geometry (not its corners).
double ray_length(const PerspectiveCamera& cam, int x, int y, int w, int h) {
  const double tan_v = std::tan(double(cam.fov_y_deg) * 3.14159265358979323846 / 360.0);
  const double u = (x + 0.5) / w, v = 1.0 - (y + 0.5) / h;
  const double rx = (2 * u - 1) * tan_v * double(cam.aspect), ry = (2 * v - 1) * tan_v;
  return std::sqrt(rx * rx + ry * ry + 1.0);
}

TEST(DepthKinds, EyeDepthRoundTripsThroughLinearEyeDepth) {
  for (bool reversed : {false, true}) {
    const CameraParams p = make_camera_params(camera(reversed));
    double worst = 0;
    for (double eye = 0.3; eye < 999.0; eye *= 1.07) {
      const float raw = float(raw_from_eye_depth(eye, p));
      EXPECT_GE(raw, 0.0f);
      EXPECT_LE(raw, 1.0f);
      worst = std::max(worst, std::fabs(linear_eye_depth(raw, p) - eye) / eye);
    }
    std::printf("[ worst    ] eye -> raw -> eye (%s Z): rel %.2e\n", reversed ? "reversed" : "conventional", worst);
    // float raw depth resolves eye depth to ~far/near * 2^-24 relative in conventional Z.
    EXPECT_LE(worst, reversed ? 1e-6 : 3e-4);
  }
}

TEST(DepthKinds, BackgroundIsTheSkyValue) {
  for (bool reversed : {false, true}) {
    const CameraParams p = make_camera_params(camera(reversed));
    const double sky = reversed ? 0.0 : 1.0;
    for (double bg : {0.0, -1.0, 1000.0, 5000.0, std::numeric_limits<double>::infinity(),
                      -std::numeric_limits<double>::infinity(), std::numeric_limits<double>::quiet_NaN()})
      EXPECT_EQ(raw_from_eye_depth(bg, p), sky) << bg;
    EXPECT_EQ(sky_raw_depth(p), float(sky));
    EXPECT_NE(raw_from_eye_depth(999.0, p), sky);
  }
}

TEST(DepthKinds, DistanceIsDividedByThePixelsRayLength) {
  const PerspectiveCamera cam = camera(false);
  const CameraParams p = make_camera_params(cam);
  const int w = 33, h = 21;
  DepthImage d(w, h);
  const auto ray_len = [&](int x, int y) { return ray_length(cam, x, y, w, h); };
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) d.at(x, y) = float((1.0 + (17 * (x + y * w)) % 900) * ray_len(x, y));
  d.at(0, 0) = std::numeric_limits<float>::infinity();
  d.at(1, 0) = 0.0f;
  d.at(2, 0) = float(1000.0 * ray_len(2, 0) * 1.001);  // beyond the far plane along its ray
  const DepthImage distance = d;
  to_raw_depth(d, DepthKind::distance, p);
  double worst = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      if (y == 0 && x < 3) {
        EXPECT_EQ(d.at(x, y), 1.0f) << x;
        continue;
      }
      const double back = linear_eye_depth(d.at(x, y), p) * ray_len(x, y);
      worst = std::max(worst, std::fabs(back - distance.at(x, y)) / distance.at(x, y));
    }
  std::printf("[ worst    ] distance -> raw -> distance: rel %.2e\n", worst);
  EXPECT_LE(worst, 3e-4);
  // Eye kind ignores the ray; raw kind changes nothing.
  DepthImage eye = distance, raw = distance;
  to_raw_depth(eye, DepthKind::eye, p);
  EXPECT_EQ(eye.at(5, 5), float(raw_from_eye_depth(distance.at(5, 5), p)));
  EXPECT_NE(eye.at(0, 10), d.at(0, 10));
  to_raw_depth(raw, DepthKind::raw, p);
  EXPECT_EQ(raw.at(5, 5), distance.at(5, 5));
}

// The other projections: orthographic (Linear01Depth = x raw + y, eye = Linear01Depth far) in both Z
// directions and the infinite far plane (eye = near / raw) round-trip through their own formulas;
// distance on the infinite far plane divides by the ray normalised to view z = 1; distance with an
// orthographic camera (parallel rays) is refused.
TEST(DepthKinds, OrthographicAndInfiniteFarRoundTrip) {
  for (bool reversed : {false, true}) {
    OrthographicCamera o;
    o.near_plane = 0.3f;
    o.far_plane = 1000.0f;
    o.reversed_z = reversed;
    const CameraParams p = make_camera_params(o);
    double worst = 0;
    for (double eye = 0.31; eye < 999.0; eye *= 1.07) {
      const double raw = float(raw_from_eye_depth(eye, p));
      const double back = (double(p.zbuffer_params.x) * raw + double(p.zbuffer_params.y)) * double(p.far_plane());
      worst = std::max(worst, std::fabs(back - eye) / eye);
    }
    std::printf("[ worst    ] orthographic eye -> raw -> eye (%s Z): rel %.2e\n", reversed ? "reversed" : "conventional",
                worst);
    EXPECT_LE(worst, 2e-4);  // float raw resolves far * 2^-24 in eye depth: 6e-5 of 0.31 + rounding
    EXPECT_EQ(raw_from_eye_depth(2000.0, p), double(sky_raw_depth(p)));
    DepthImage d(4, 3, 5.0f);
    EXPECT_THROW(to_raw_depth(d, DepthKind::distance, p), Error);
    EXPECT_EQ(d.at(1, 1), 5.0f);  // refused before any pixel changed
  }
  PerspectiveCamera c = camera(true);
  c.infinite_far = true;
  const CameraParams p = make_camera_params(c);
  double worst = 0;
  for (double eye = 0.31; eye < 1e7; eye *= 1.07) {
    const double raw = float(raw_from_eye_depth(eye, p));
    worst = std::max(worst, std::fabs(double(p.near_plane()) / raw - eye) / eye);
  }
  std::printf("[ worst    ] infinite far eye -> raw -> eye: rel %.2e\n", worst);
  EXPECT_LE(worst, 1e-7);
  EXPECT_EQ(raw_from_eye_depth(std::numeric_limits<double>::infinity(), p), 0.0);
  const int w = 9, h = 5;
  DepthImage d(w, h, 42.0f);
  to_raw_depth(d, DepthKind::distance, p);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double eye = double(p.near_plane()) / double(d.at(x, y));
      EXPECT_NEAR(eye * ray_length(c, x, y, w, h), 42.0, 42.0 * 1e-6) << x << ", " << y;
    }
}

TEST(DepthKinds, ParseNamesTheBadValue) {
  EXPECT_EQ(parse_depth_kind("eye"), DepthKind::eye);
  EXPECT_EQ(parse_depth_kind("distance"), DepthKind::distance);
  EXPECT_EQ(parse_depth_kind("raw"), DepthKind::raw);
  try {
    parse_depth_kind("linear");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("'linear'"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace fogcl::test
