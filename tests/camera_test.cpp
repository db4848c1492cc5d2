// Unit tests of the camera constants (docs/DESIGN.md §2): _ZBufferParams, _ProjectionParams, frustum
// corners, Unity corner order, camera recovery from GLM projection matrices and validation.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "test_support.h"

#include <glm/ext/matrix_clip_space.hpp>
#include <glm/trigonometric.hpp>

#include "fogcl/camera.h"
#include "fogcl/error.h"

namespace fogcl {
namespace {

using test::error_of;
using test::num;

constexpr double kPi = 3.14159265358979323846;

PerspectiveCamera cam(float fov, float aspect, float n, float f, bool reversed = false) {
  PerspectiveCamera c;
  c.fov_y_deg = fov;
  c.aspect = aspect;
  c.near_plane = n;
  c.far_plane = f;
  c.reversed_z = reversed;
  return c;
}

// A spread of cameras: Unity's default, wide/narrow fov, small/large aspect, near/far ratios.
std::vector<PerspectiveCamera> sample_cameras(bool reversed) {
  return {cam(60.0f, 16.0f / 9.0f, 0.3f, 1000.0f, reversed), cam(90.0f, 1.0f, 0.1f, 100.0f, reversed),
          cam(30.0f, 2.35f, 1.0f, 500.0f, reversed),        cam(120.0f, 0.5f, 0.01f, 10.0f, reversed),
          cam(10.0f, 4.0f / 3.0f, 2.0f, 3.0f, reversed),    cam(75.0f, 1.5f, 0.05f, 20000.0f, reversed)};
}

double rel(double got, double want) {
  const double d = std::fabs(got - want);
  return want == 0.0 ? d : d / std::fabs(want);
}



// ---------------------------------------------------------------------------------------------
// make_camera_params

TEST(CameraTest, ZBufferParamsConventionalExactFloat) {
  for (const PerspectiveCamera& c : sample_cameras(false)) {
    const CameraParams p = make_camera_params(c);
    const float n = c.near_plane, f = c.far_plane;
    const float y = f / n;
    const float x = 1.0f - y;
    EXPECT_EQ(p.zbuffer_params.x, x) << "near " << n << " far " << f;
    EXPECT_EQ(p.zbuffer_params.y, y) << "near " << n << " far " << f;
    EXPECT_EQ(p.zbuffer_params.z, x / f) << "near " << n << " far " << f;
    EXPECT_EQ(p.zbuffer_params.w, y / f) << "near " << n << " far " << f;
    EXPECT_FALSE(p.reversed_z);
  }
}

TEST(CameraTest, ZBufferParamsReversedExactFloat) {
  for (const PerspectiveCamera& c : sample_cameras(true)) {
    const CameraParams p = make_camera_params(c);
    const float n = c.near_plane, f = c.far_plane;
    const float x = -1.0f + f / n;
    EXPECT_EQ(p.zbuffer_params.x, x) << "near " << n << " far " << f;
    EXPECT_EQ(p.zbuffer_params.y, 1.0f) << "near " << n << " far " << f;
    EXPECT_EQ(p.zbuffer_params.z, x / f) << "near " << n << " far " << f;
    EXPECT_EQ(p.zbuffer_params.w, 1.0f / f) << "near " << n << " far " << f;
    EXPECT_TRUE(p.reversed_z);
  }
}

TEST(CameraTest, ProjectionParams) {
  for (bool reversed : {false, true}) {
    for (const PerspectiveCamera& c : sample_cameras(reversed)) {
      const CameraParams p = make_camera_params(c);
      EXPECT_EQ(p.projection_params.x, 1.0f);
      EXPECT_EQ(p.projection_params.y, c.near_plane);
      EXPECT_EQ(p.projection_params.z, c.far_plane);
      EXPECT_EQ(p.projection_params.w, 1.0f / c.far_plane);
      EXPECT_EQ(p.near_plane(), c.near_plane);
      EXPECT_EQ(p.far_plane(), c.far_plane);
    }
  }
}

TEST(CameraTest, FrustumCornersFarPlaneInQuadOrder) {
  double worst = 0;
  for (bool reversed : {false, true}) {
    for (const PerspectiveCamera& c : sample_cameras(reversed)) {
      const CameraParams p = make_camera_params(c);
      const double f = c.far_plane;
      const double half_h = std::tan(double(c.fov_y_deg) * 0.5 * kPi / 180.0) * f;
      const double half_w = half_h * double(c.aspect);
      // index u + 2v: (u, v) = (0,0) BL, (1,0) BR, (0,1) TL, (1,1) TR.
      for (int i = 0; i < 4; ++i) {
        const int u = i & 1, v = i >> 1;
        const double want_x = (u ? 1 : -1) * half_w, want_y = (v ? 1 : -1) * half_h;
        const glm::vec3 got = p.frustum_corners[std::size_t(i)];
        const double ex = rel(got.x, want_x), ey = rel(got.y, want_y);
        worst = std::max({worst, ex, ey});
        EXPECT_LE(ex, 1e-6) << "corner " << i << " x " << got.x << " want " << want_x;
        EXPECT_LE(ey, 1e-6) << "corner " << i << " y " << got.y << " want " << want_y;
        EXPECT_EQ(got.z, c.far_plane) << "corner " << i;
      }
      EXPECT_LT(p.frustum_corners[kBottomLeft].x, 0.0f);
      EXPECT_LT(p.frustum_corners[kBottomLeft].y, 0.0f);
      EXPECT_GT(p.frustum_corners[kBottomRight].x, 0.0f);
      EXPECT_LT(p.frustum_corners[kBottomRight].y, 0.0f);
      EXPECT_LT(p.frustum_corners[kTopLeft].x, 0.0f);
      EXPECT_GT(p.frustum_corners[kTopLeft].y, 0.0f);
      EXPECT_GT(p.frustum_corners[kTopRight].x, 0.0f);
      EXPECT_GT(p.frustum_corners[kTopRight].y, 0.0f);
    }
  }
  std::printf("[ info ] frustum corners: worst relative error vs double %.3g\n", worst);
}

TEST(CameraTest, CornerEnumIsQuadIndex) {
  EXPECT_EQ(int(kBottomLeft), 0 + 2 * 0);
  EXPECT_EQ(int(kBottomRight), 1 + 2 * 0);
  EXPECT_EQ(int(kTopLeft), 0 + 2 * 1);
  EXPECT_EQ(int(kTopRight), 1 + 2 * 1);
}

TEST(CameraTest, Linear01DepthEndpointsFromParams) {
  double worst = 0, worst_eye_far = 0;
  for (bool reversed : {false, true}) {
    for (const PerspectiveCamera& c : sample_cameras(reversed)) {
      const CameraParams p = make_camera_params(c);
      const double x = p.zbuffer_params.x, y = p.zbuffer_params.y;
      const double z = p.zbuffer_params.z, w = p.zbuffer_params.w;
      const auto linear01 = [&](double raw) { return 1.0 / (x * raw + y); };
      const auto eye = [&](double raw) { return 1.0 / (z * raw + w); };
      const double raw_near = reversed ? 1.0 : 0.0, raw_far = reversed ? 0.0 : 1.0;
      const double n = c.near_plane, f = c.far_plane;
      const double e[4] = {rel(linear01(raw_far), 1.0), rel(linear01(raw_near), n / f),
                           rel(eye(raw_far), f), rel(eye(raw_near), n)};
      worst = std::max({worst, e[0], e[1], e[3]});
      EXPECT_LE(e[0], 1e-6) << "Linear01Depth(far raw) = " << linear01(raw_far) << " reversed " << reversed;
      EXPECT_LE(e[1], 1e-6) << "Linear01Depth(near raw) = " << linear01(raw_near) << " want " << n / f;
      EXPECT_LE(e[3], 1e-6) << "LinearEyeDepth(near raw) = " << eye(raw_near) << " want " << n;
      if (reversed) {
        worst = std::max(worst, e[2]);
        EXPECT_LE(e[2], 1e-6) << "LinearEyeDepth(far raw) = " << eye(raw_far) << " want " << f;
      } else {
        // Conventional Z: z + w = (x + y) / far cancels (x ~ -y), so float-rounded z and w only
        // give LinearEyeDepth(1) to about 2^-24 * far/near relative, as in Unity itself. The spec
        // linearises with Linear01Depth * far, which is exact at 1; only report this one.
        worst_eye_far = std::max(worst_eye_far, e[2]);
        EXPECT_LE(e[2], 4.0 * std::ldexp(1.0, -24) * (f / n)) << "LinearEyeDepth(far raw) = " << eye(raw_far);
      }
    }
  }
  std::printf("[ info ] Linear01Depth/LinearEyeDepth endpoints: worst relative error %.3g "
              "(conventional LinearEyeDepth(1), float-conditioned: %.3g)\n", worst, worst_eye_far);
}

TEST(CameraTest, ConventionalLinear01DepthOfOneIsExactlyOne) {
  // Float arithmetic keeps x = 1 - y exact, so Linear01Depth(1) == 1 in float too.
  for (const PerspectiveCamera& c : sample_cameras(false)) {
    const CameraParams p = make_camera_params(c);
    EXPECT_EQ(1.0f / (p.zbuffer_params.x * 1.0f + p.zbuffer_params.y), 1.0f) << "far " << c.far_plane;
  }
}

TEST(CameraTest, MakeCameraParamsValidates) {
  EXPECT_THROW(make_camera_params(cam(60.0f, 1.0f, -1.0f, 10.0f)), Error);
  EXPECT_THROW(make_camera_params(cam(60.0f, 1.0f, 1.0f, 1.0f)), Error);
}

// ---------------------------------------------------------------------------------------------
// Unity corner order

TEST(CameraTest, CornersFromUnityOrder) {
  const glm::vec3 bl(-1, -2, 3), tl(-4, 5, 6), tr(7, 8, 9), br(10, -11, 12);
  const std::array<glm::vec3, 4> unity = {bl, tl, tr, br};
  const std::array<glm::vec3, 4> out = corners_from_unity_order(unity);
  EXPECT_EQ(out[kBottomLeft], bl);
  EXPECT_EQ(out[kBottomRight], br);
  EXPECT_EQ(out[kTopLeft], tl);
  EXPECT_EQ(out[kTopRight], tr);
}

TEST(CameraTest, CornersFromUnityOrderMatchesMakeCameraParams) {
  const CameraParams p = make_camera_params(cam(60.0f, 16.0f / 9.0f, 0.3f, 1000.0f));
  const auto& c = p.frustum_corners;
  const std::array<glm::vec3, 4> unity = {c[kBottomLeft], c[kTopLeft], c[kTopRight], c[kBottomRight]};
  EXPECT_EQ(corners_from_unity_order(unity), c);
}

// ---------------------------------------------------------------------------------------------
// camera_from_projection

struct RoundTripError {
  double fov = 0, aspect = 0, near_plane = 0, far_plane = 0, params = 0;
};

// Checks the recovered camera and its constants against the original; returns worst errors.
void check_round_trip(const char* what, const glm::mat4& m, ClipDepth depth, const PerspectiveCamera& want,
                      RoundTripError& worst) {
  SCOPED_TRACE(std::string(what) + " fov " + num(want.fov_y_deg) + " aspect " + num(want.aspect) +
               " near " + num(want.near_plane) + " far " + num(want.far_plane));
  PerspectiveCamera got;
  ASSERT_NO_THROW(got = camera_from_projection(m, depth));
  EXPECT_EQ(got.reversed_z, want.reversed_z);
  const double e_fov = rel(got.fov_y_deg, want.fov_y_deg), e_aspect = rel(got.aspect, want.aspect);
  const double e_near = rel(got.near_plane, want.near_plane), e_far = rel(got.far_plane, want.far_plane);
  EXPECT_LE(e_fov, 1e-4) << "fov " << got.fov_y_deg;
  EXPECT_LE(e_aspect, 1e-4) << "aspect " << got.aspect;
  EXPECT_LE(e_near, 1e-4) << "near " << got.near_plane;
  EXPECT_LE(e_far, 1e-4) << "far " << got.far_plane;
  worst.fov = std::max(worst.fov, e_fov);
  worst.aspect = std::max(worst.aspect, e_aspect);
  worst.near_plane = std::max(worst.near_plane, e_near);
  worst.far_plane = std::max(worst.far_plane, e_far);

  const CameraParams pg = make_camera_params(got), pw = make_camera_params(want);
  EXPECT_EQ(pg.reversed_z, pw.reversed_z);
  for (int k = 0; k < 4; ++k) {
    const double ez = rel(pg.zbuffer_params[k], pw.zbuffer_params[k]);
    const double ep = rel(pg.projection_params[k], pw.projection_params[k]);
    EXPECT_LE(ez, 1e-5) << "_ZBufferParams[" << k << "] " << pg.zbuffer_params[k] << " want "
                        << pw.zbuffer_params[k];
    EXPECT_LE(ep, 1e-5) << "_ProjectionParams[" << k << "] " << pg.projection_params[k] << " want "
                        << pw.projection_params[k];
    worst.params = std::max({worst.params, ez, ep});
    for (int a = 0; a < 3; ++a) {
      const double ec = rel(pg.frustum_corners[std::size_t(k)][a], pw.frustum_corners[std::size_t(k)][a]);
      EXPECT_LE(ec, 1e-5) << "corner " << k << " component " << a;
      worst.params = std::max(worst.params, ec);
    }
  }
}

// Cameras whose far/near ratio keeps the float matrix well conditioned enough for 1e-5 on the
// recovered constants (the far plane's relative error grows like 2^-24 * far/near).
std::vector<PerspectiveCamera> round_trip_cameras() {
  return {cam(60.0f, 16.0f / 9.0f, 1.0f, 50.0f), cam(90.0f, 1.0f, 0.1f, 10.0f), cam(30.0f, 2.35f, 1.0f, 20.0f),
          cam(120.0f, 0.5f, 0.5f, 5.0f),         cam(10.0f, 4.0f / 3.0f, 2.0f, 3.0f),
          cam(45.0f, 1.0f, 10.0f, 100.0f)};
}

void print_worst(const char* what, const RoundTripError& w) {
  std::printf("[ info ] %s round trip worst relative error: fov %.3g aspect %.3g near %.3g far %.3g constants %.3g\n",
              what, w.fov, w.aspect, w.near_plane, w.far_plane, w.params);
}

TEST(CameraTest, FromProjectionGlmPerspectiveRhNegOneToOne) {
  RoundTripError worst;
  for (const PerspectiveCamera& c : round_trip_cameras()) {
    const glm::mat4 m = glm::perspectiveRH_NO(glm::radians(c.fov_y_deg), c.aspect, c.near_plane, c.far_plane);
    check_round_trip("perspectiveRH_NO", m, ClipDepth::negative_one_to_one, c, worst);
    // glm::perspective is RH_NO unless GLM_FORCE_* says otherwise; it must behave the same.
    const glm::mat4 m2 = glm::perspective(glm::radians(c.fov_y_deg), c.aspect, c.near_plane, c.far_plane);
    check_round_trip("perspective", m2, ClipDepth::negative_one_to_one, c, worst);
  }
  print_worst("glm::perspective (RH, -1..1)", worst);
}

TEST(CameraTest, FromProjectionGlmPerspectiveLhZeroToOne) {
  RoundTripError worst;
  for (const PerspectiveCamera& c : round_trip_cameras()) {
    const glm::mat4 m = glm::perspectiveLH_ZO(glm::radians(c.fov_y_deg), c.aspect, c.near_plane, c.far_plane);
    check_round_trip("perspectiveLH_ZO", m, ClipDepth::zero_to_one, c, worst);
  }
  print_worst("glm::perspectiveLH_ZO", worst);
}

TEST(CameraTest, FromProjectionGlmPerspectiveRhZeroToOne) {
  RoundTripError worst;
  for (const PerspectiveCamera& c : round_trip_cameras()) {
    const glm::mat4 m = glm::perspectiveRH_ZO(glm::radians(c.fov_y_deg), c.aspect, c.near_plane, c.far_plane);
    check_round_trip("perspectiveRH_ZO", m, ClipDepth::zero_to_one, c, worst);
  }
  print_worst("glm::perspectiveRH_ZO", worst);
}

TEST(CameraTest, FromProjectionReversedZZeroToOne) {
  RoundTripError worst;
  for (PerspectiveCamera c : round_trip_cameras()) {
    c.reversed_z = true;
    // Swapping near and far gives depth 1 at near, 0 at far.
    const glm::mat4 m = glm::perspectiveRH_ZO(glm::radians(c.fov_y_deg), c.aspect, c.far_plane, c.near_plane);
    check_round_trip("reversed perspectiveRH_ZO", m, ClipDepth::zero_to_one, c, worst);
    const glm::mat4 lh = glm::perspectiveLH_ZO(glm::radians(c.fov_y_deg), c.aspect, c.far_plane, c.near_plane);
    check_round_trip("reversed perspectiveLH_ZO", lh, ClipDepth::zero_to_one, c, worst);
  }
  print_worst("reversed-Z ZO", worst);
}

TEST(CameraTest, FromProjectionUnityDefaultCameraWithinFloatConditioning) {
  // Unity's default camera (0.3 .. 1000): the float matrix itself only pins the far plane down to
  // about 2^-24 * far/near relative; the recovery must stay within a small multiple of that.
  const PerspectiveCamera c = cam(60.0f, 16.0f / 9.0f, 0.3f, 1000.0f);
  const double bound = 8.0 * std::ldexp(1.0, -24) * (c.far_plane / c.near_plane);
  const glm::mat4 ms[] = {glm::perspectiveRH_NO(glm::radians(c.fov_y_deg), c.aspect, c.near_plane, c.far_plane),
                          glm::perspectiveRH_ZO(glm::radians(c.fov_y_deg), c.aspect, c.near_plane, c.far_plane),
                          glm::perspectiveLH_ZO(glm::radians(c.fov_y_deg), c.aspect, c.near_plane, c.far_plane)};
  const ClipDepth ds[] = {ClipDepth::negative_one_to_one, ClipDepth::zero_to_one, ClipDepth::zero_to_one};
  double worst_near = 0, worst_far = 0, worst_fov = 0;
  for (int i = 0; i < 3; ++i) {
    const PerspectiveCamera got = camera_from_projection(ms[i], ds[i]);
    EXPECT_FALSE(got.reversed_z);
    worst_near = std::max(worst_near, rel(got.near_plane, c.near_plane));
    worst_far = std::max(worst_far, rel(got.far_plane, c.far_plane));
    worst_fov = std::max({worst_fov, rel(got.fov_y_deg, c.fov_y_deg), rel(got.aspect, c.aspect)});
  }
  std::printf("[ info ] Unity default camera round trip: near %.3g far %.3g fov/aspect %.3g (bound %.3g)\n",
              worst_near, worst_far, worst_fov, bound);
  EXPECT_LE(worst_near, 1e-4);
  EXPECT_LE(worst_far, bound);
  EXPECT_LE(worst_fov, 1e-4);
}

TEST(CameraTest, FromProjectionWrongClipDepthIsNotSilentlyTheSame) {
  // Reading an RH_NO matrix as ZO gives another near plane: the clip_depth argument matters.
  const PerspectiveCamera c = cam(60.0f, 1.0f, 1.0f, 10.0f);
  const glm::mat4 m = glm::perspectiveRH_NO(glm::radians(c.fov_y_deg), c.aspect, c.near_plane, c.far_plane);
  PerspectiveCamera got;
  try {
    got = camera_from_projection(m, ClipDepth::zero_to_one);
  } catch (const Error&) {
    return;  // rejecting it is fine too
  }
  EXPECT_GT(rel(got.near_plane, c.near_plane), 1e-3);
}

TEST(CameraTest, FromProjectionRejectsOrthographic) {
  const glm::mat4 m = glm::ortho(-1.0f, 1.0f, -1.0f, 1.0f, 0.1f, 100.0f);
  const std::string msg = error_of([&] { camera_from_projection(m); });
  EXPECT_MSG_HAS(msg, "orthographic");
}

TEST(CameraTest, FromProjectionRejectsOffCentreFrustum) {
  const glm::mat4 m = glm::frustum(-0.5f, 1.0f, -0.4f, 0.6f, 0.3f, 100.0f);
  const std::string msg = error_of([&] { camera_from_projection(m); });
  EXPECT_MSG_HAS(msg, "off-centre");
  // Off-centre vertically only.
  const glm::mat4 m2 = glm::frustum(-1.0f, 1.0f, -0.4f, 0.6f, 0.3f, 100.0f);
  EXPECT_THROW(camera_from_projection(m2), Error);
}

TEST(CameraTest, FromProjectionRejectsYFlip) {
  glm::mat4 m = glm::perspective(glm::radians(60.0f), 1.5f, 0.3f, 100.0f);
  m[1][1] = -m[1][1];
  const std::string msg = error_of([&] { camera_from_projection(m); });
  EXPECT_MSG_HAS(msg, num(m[1][1]));
  EXPECT_MSG_HAS(msg, "m[1][1]");
}

TEST(CameraTest, FromProjectionRejectsInfiniteFar) {
  const glm::mat4 m = glm::infinitePerspective(glm::radians(60.0f), 1.5f, 0.3f);
  const std::string msg = error_of([&] { camera_from_projection(m); });
  EXPECT_MSG_HAS(msg, "infinite");
}

// ---------------------------------------------------------------------------------------------
// validate(PerspectiveCamera)

TEST(CameraTest, ValidateAcceptsSaneCameras) {
  for (bool reversed : {false, true})
    for (const PerspectiveCamera& c : sample_cameras(reversed)) EXPECT_NO_THROW(validate(c));
  EXPECT_NO_THROW(validate(PerspectiveCamera{}));
}

TEST(CameraTest, ValidateRejectsBadNear) {
  {
    const std::string msg = error_of([] { validate(cam(60.0f, 1.0f, 0.0f, 10.0f)); });
    EXPECT_MSG_HAS(msg, "near");
    EXPECT_MSG_HAS(msg, "got 0");
  }
  {
    const std::string msg = error_of([] { validate(cam(60.0f, 1.0f, -0.5f, 10.0f)); });
    EXPECT_MSG_HAS(msg, "near");
    EXPECT_MSG_HAS(msg, "-0.5");
  }
  {
    const std::string msg = error_of([] { validate(cam(60.0f, 1.0f, std::nanf(""), 10.0f)); });
    EXPECT_MSG_HAS(msg, "near");
    EXPECT_MSG_HAS(msg, "nan");
  }
}

TEST(CameraTest, ValidateRejectsBadFar) {
  {
    const std::string msg = error_of([] { validate(cam(60.0f, 1.0f, 2.0f, 1.5f)); });
    EXPECT_MSG_HAS(msg, "far");
    EXPECT_MSG_HAS(msg, "1.5");
  }
  {
    const std::string msg = error_of([] { validate(cam(60.0f, 1.0f, 2.0f, 2.0f)); });
    EXPECT_MSG_HAS(msg, "far");
  }
  {
    const float inf = std::numeric_limits<float>::infinity();
    const std::string msg = error_of([&] { validate(cam(60.0f, 1.0f, 0.3f, inf)); });
    EXPECT_MSG_HAS(msg, "far");
    EXPECT_MSG_HAS(msg, "inf");
  }
  {
    const std::string msg = error_of([] { validate(cam(60.0f, 1.0f, 0.3f, std::nanf(""))); });
    EXPECT_MSG_HAS(msg, "far");
    EXPECT_MSG_HAS(msg, "nan");
  }
}

TEST(CameraTest, ValidateRejectsBadFov) {
  for (float fov : {0.0f, 180.0f, -10.0f, 200.0f}) {
    const std::string msg = error_of([&] { validate(cam(fov, 1.0f, 0.3f, 100.0f)); });
    EXPECT_MSG_HAS(msg, "fov");
    EXPECT_MSG_HAS(msg, num(fov));
  }
  const std::string msg = error_of([] { validate(cam(std::nanf(""), 1.0f, 0.3f, 100.0f)); });
  EXPECT_MSG_HAS(msg, "fov");
  EXPECT_MSG_HAS(msg, "nan");
}

TEST(CameraTest, ValidateRejectsBadAspect) {
  for (float aspect : {0.0f, -1.5f}) {
    const std::string msg = error_of([&] { validate(cam(60.0f, aspect, 0.3f, 100.0f)); });
    EXPECT_MSG_HAS(msg, "aspect");
    EXPECT_MSG_HAS(msg, num(aspect));
  }
  for (float aspect : {std::nanf(""), std::numeric_limits<float>::infinity()}) {
    const std::string msg = error_of([&] { validate(cam(60.0f, aspect, 0.3f, 100.0f)); });
    EXPECT_MSG_HAS(msg, "aspect");
  }
}

// ---------------------------------------------------------------------------------------------
// validate(CameraParams)

TEST(CameraTest, ValidateParamsAcceptsMadeParams) {
  for (bool reversed : {false, true})
    for (const PerspectiveCamera& c : sample_cameras(reversed)) EXPECT_NO_THROW(validate(make_camera_params(c)));
}

TEST(CameraTest, ValidateParamsRejectsNaNZBufferParams) {
  for (int k = 0; k < 4; ++k) {
    CameraParams p = make_camera_params(PerspectiveCamera{});
    p.zbuffer_params[k] = std::nanf("");
    const std::string msg = error_of([&] { validate(p); });
    EXPECT_MSG_HAS(msg, "_ZBufferParams");
    EXPECT_MSG_HAS(msg, "nan");
  }
}

TEST(CameraTest, ValidateParamsRejectsBadNearFar) {
  {
    CameraParams p = make_camera_params(PerspectiveCamera{});
    p.projection_params.y = 0.0f;
    const std::string msg = error_of([&] { validate(p); });
    EXPECT_MSG_HAS(msg, "near");
  }
  {
    CameraParams p = make_camera_params(PerspectiveCamera{});
    p.projection_params.y = -2.0f;
    const std::string msg = error_of([&] { validate(p); });
    EXPECT_MSG_HAS(msg, "near");
    EXPECT_MSG_HAS(msg, "-2");
  }
  {
    CameraParams p = make_camera_params(PerspectiveCamera{});
    p.projection_params.z = p.projection_params.y;  // far == near
    const std::string msg = error_of([&] { validate(p); });
    EXPECT_MSG_HAS(msg, "far");
  }
  {
    CameraParams p = make_camera_params(PerspectiveCamera{});
    p.projection_params.z = 0.1f;  // far < near (0.3)
    const std::string msg = error_of([&] { validate(p); });
    EXPECT_MSG_HAS(msg, "far");
    EXPECT_MSG_HAS(msg, "0.1");
  }
}

TEST(CameraTest, ValidateParamsRejectsNaNCorner) {
  for (int i = 0; i < 4; ++i) {
    for (int k = 0; k < 3; ++k) {
      CameraParams p = make_camera_params(PerspectiveCamera{});
      p.frustum_corners[std::size_t(i)][k] = std::nanf("");
      const std::string msg = error_of([&] { validate(p); });
      EXPECT_MSG_HAS(msg, "corner");
      EXPECT_MSG_HAS(msg, "nan");
    }
  }
}

TEST(CameraTest, ValidateParamsRejectsNonPerspectiveZBuffer) {
  CameraParams p = make_camera_params(PerspectiveCamera{});
  p.zbuffer_params.y = -1.0f;  // Linear01Depth(0) negative
  EXPECT_THROW(validate(p), Error);
}

}  // namespace
}  // namespace fogcl
