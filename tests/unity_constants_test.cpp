// Raw Unity constants, safely (docs/DESIGN.md §2.1): camera_params_from_unity() derives reversed Z
// and the projection from the values, and validate(CameraParams) rejects every inconsistency that
// used to give a silently unfogged or wrongly fogged frame, naming the value and the rule.
#include "test_support.h"

namespace fogcl::test {
namespace {

// What a Unity renderer hands over for `camera`, computed here from Unity's documented formulas
// (independently of the library's): _ZBufferParams, _ProjectionParams, corners in Unity's order.
UnityCameraConstants unity_constants(const PerspectiveCamera& camera) {
  const float n = camera.near_plane, f = camera.far_plane;
  UnityCameraConstants u;
  if (camera.reversed_z)
    u.zbuffer_params = glm::vec4(-1.0f + f / n, 1.0f, (-1.0f + f / n) / f, 1.0f / f);
  else
    u.zbuffer_params = glm::vec4(1.0f - f / n, f / n, (1.0f - f / n) / f, (f / n) / f);
  u.projection_params = glm::vec4(1.0f, n, f, 1.0f / f);
  const auto c = make_camera_params(camera).frustum_corners;
  u.frustum_corners = {c[kBottomLeft], c[kTopLeft], c[kTopRight], c[kBottomRight]};  // Unity's order
  return u;
}

UnityCameraConstants unity_constants(const OrthographicCamera& camera) {
  PerspectiveCamera as_perspective;  // Unity fills _ZBufferParams from near and far alike
  as_perspective.near_plane = camera.near_plane;
  as_perspective.far_plane = camera.far_plane;
  as_perspective.reversed_z = camera.reversed_z;
  UnityCameraConstants u = unity_constants(as_perspective);
  const auto c = make_camera_params(camera).frustum_corners;
  u.frustum_corners = {c[kBottomLeft], c[kTopLeft], c[kTopRight], c[kBottomRight]};
  u.ortho_params = glm::vec4(camera.ortho_size * camera.aspect, camera.ortho_size, 0.0f, 1.0f);
  return u;
}

bool same(const CameraParams& a, const CameraParams& b) {
  return a.zbuffer_params == b.zbuffer_params && a.projection_params == b.projection_params &&
         a.frustum_corners == b.frustum_corners && a.reversed_z == b.reversed_z && a.projection == b.projection;
}

TEST(UnityConstants, PerspectiveBothZDirectionsGiveTheLibrarysOwnParams) {
  for (const bool reversed : {false, true}) {
    PerspectiveCamera camera;
    camera.reversed_z = reversed;
    camera.near_plane = 0.3f;
    camera.far_plane = 1000.0f;
    const CameraParams got = camera_params_from_unity(unity_constants(camera));
    const CameraParams want = make_camera_params(camera);
    EXPECT_EQ(got.reversed_z, reversed);
    EXPECT_EQ(got.projection, Projection::perspective);
    EXPECT_EQ(got.frustum_corners, want.frustum_corners) << "reordered from Unity's order";
    float worst = 0;
    for (int k = 0; k < 4; ++k)
      worst = std::max(worst, std::fabs(got.zbuffer_params[k] - want.zbuffer_params[k]) /
                                  std::max(std::fabs(want.zbuffer_params[k]), 1e-30f));
    std::printf("[ worst    ] %s: relative _ZBufferParams difference to make_camera_params %.2e\n",
                reversed ? "reversed" : "conventional", double(worst));
    EXPECT_LE(worst, 1e-6f);
  }
}

TEST(UnityConstants, OrthographicBothZDirectionsGiveTheLibrarysOwnParams) {
  for (const bool reversed : {false, true}) {
    OrthographicCamera camera;
    camera.reversed_z = reversed;
    const CameraParams got = camera_params_from_unity(unity_constants(camera));
    EXPECT_TRUE(same(got, make_camera_params(camera))) << (reversed ? "reversed" : "conventional");
  }
}

TEST(UnityConstants, FactoryRejectsWhatUnityCannotHaveGiven) {
  const UnityCameraConstants good = unity_constants(PerspectiveCamera{});
  UnityCameraConstants u = good;
  u.frustum_corners = make_camera_params(PerspectiveCamera{}).frustum_corners;  // fogcl's order already
  EXPECT_MSG_HAS(error_of([&] { camera_params_from_unity(u); }), "not in Unity's CalculateFrustumCorners order");
  u = good;
  u.ortho_params.w = 0.5f;
  EXPECT_MSG_HAS(error_of([&] { camera_params_from_unity(u); }), "unity_OrthoParams.w must be 0");
  u = good;
  u.projection_params.z = INFINITY;
  EXPECT_MSG_HAS(error_of([&] { camera_params_from_unity(u); }), "finite far plane");
  u = good;
  u.projection_params.x = -1.0f;
  EXPECT_MSG_HAS(error_of([&] { camera_params_from_unity(u); }), "_ProjectionParams.x = -1");
  // Orthographic corners that do not match unity_OrthoParams' extents.
  UnityCameraConstants o = unity_constants(OrthographicCamera{});
  o.ortho_params.y *= 2.0f;
  EXPECT_MSG_HAS(error_of([&] { camera_params_from_unity(o); }), "unity_OrthoParams");
  // _ZBufferParams of another near/far than _ProjectionParams.
  u = good;
  u.projection_params.z = 500.0f;
  u.projection_params.w = 1.0f / 500.0f;
  for (auto& c : u.frustum_corners) c *= 0.5f;  // corners at the new far plane: only Z disagrees
  const std::string msg = error_of([&] { camera_params_from_unity(u); });
  std::printf("[ info     ] %s\n", msg.c_str());
  EXPECT_MSG_HAS(msg, "_ZBufferParams");
  EXPECT_MSG_HAS(msg, "far 500");
}

// ---- validate(CameraParams): each inconsistency that once passed silently, and its message -------------

class ValidateParams : public ::testing::Test {
 protected:
  CameraParams conventional = make_camera_params(PerspectiveCamera{});
  CameraParams reversed = [] {
    PerspectiveCamera c;
    c.reversed_z = true;
    return make_camera_params(c);
  }();
};

TEST_F(ValidateParams, ReversedZValuesWithReversedZFalse) {
  CameraParams p = reversed;
  p.reversed_z = false;  // once returned the unfogged input without a word
  const std::string msg = error_of([&] { validate(p); });
  std::printf("[ info     ] %s\n", msg.c_str());
  EXPECT_MSG_HAS(msg, "_ZBufferParams");
  EXPECT_MSG_HAS(msg, "reversed-Z values (y = 1), set reversed_z = true");
}

TEST_F(ValidateParams, ConventionalValuesWithReversedZTrue) {
  CameraParams p = conventional;
  p.reversed_z = true;
  EXPECT_MSG_HAS(error_of([&] { validate(p); }), "conventional-Z values");
}

TEST_F(ValidateParams, CornersInUnitysOrder) {
  CameraParams p = conventional;
  const auto& c = conventional.frustum_corners;
  p.frustum_corners = {c[kBottomLeft], c[kTopLeft], c[kTopRight], c[kBottomRight]};
  const std::string msg = error_of([&] { validate(p); });
  std::printf("[ info     ] %s\n", msg.c_str());
  EXPECT_MSG_HAS(msg, "not in fogcl's order");
  EXPECT_MSG_HAS(msg, "corners_from_unity_order");
}

TEST_F(ValidateParams, CornersNotAtTheFarPlane) {
  for (CameraParams p : {conventional, reversed}) {
    for (auto& corner : p.frustum_corners) corner /= corner.z;  // normalised to z = 1
    const std::string msg = error_of([&] { validate(p); });
    EXPECT_MSG_HAS(msg, "z = 1");
    EXPECT_MSG_HAS(msg, "far = 1000");
  }
  // Infinite far is the one projection whose corners lie at z = 1.
  PerspectiveCamera inf;
  inf.reversed_z = inf.infinite_far = true;
  CameraParams p = make_camera_params(inf);
  EXPECT_NO_THROW(validate(p));
  for (auto& corner : p.frustum_corners) corner *= 1000.0f;
  EXPECT_MSG_HAS(error_of([&] { validate(p); }), "normalised to z = 1");
}

TEST_F(ValidateParams, CornersNotARectangle) {
  CameraParams p = conventional;
  p.frustum_corners[kTopRight].x *= 1.5f;
  EXPECT_MSG_HAS(error_of([&] { validate(p); }), "rectangle");
}

TEST_F(ValidateParams, FlippedProjection) {
  CameraParams p = conventional;
  p.projection_params.x = -1.0f;  // once ignored
  const std::string msg = error_of([&] { validate(p); });
  EXPECT_MSG_HAS(msg, "_ProjectionParams.x = -1");
  EXPECT_MSG_HAS(msg, "flip the rows");
  p.projection_params.x = 0.5f;
  EXPECT_MSG_HAS(error_of([&] { validate(p); }), "_ProjectionParams.x must be 1 (got 0.5)");
}

TEST_F(ValidateParams, ProjectionParamsWAndNearFarAgainstZBufferParams) {
  CameraParams p = conventional;
  p.projection_params.w = 1.0f;
  EXPECT_MSG_HAS(error_of([&] { validate(p); }), "_ProjectionParams.w must be 1 / far");
  p = conventional;
  p.projection_params.z = 2000.0f;  // far no longer matches _ZBufferParams
  p.projection_params.w = 1.0f / 2000.0f;
  for (auto& corner : p.frustum_corners) corner *= 2.0f;
  EXPECT_MSG_HAS(error_of([&] { validate(p); }), "do not match near " + num(0.3f) + ", far 2000");
  p = conventional;
  p.zbuffer_params.z = 7.0f;  // z, w are not read by the kernel, but garbage is refused
  EXPECT_MSG_HAS(error_of([&] { validate(p); }), "_ZBufferParams");
}

TEST_F(ValidateParams, ValidUsesStillPass) {
  EXPECT_NO_THROW(validate(conventional));
  EXPECT_NO_THROW(validate(reversed));
  for (const bool rz : {false, true}) {
    OrthographicCamera o;
    o.reversed_z = rz;
    EXPECT_NO_THROW(validate(make_camera_params(o)));
    o.near_plane = 0.0f;  // an orthographic near plane may be 0
    EXPECT_NO_THROW(validate(make_camera_params(o)));
  }
  PerspectiveCamera inf;
  inf.reversed_z = inf.infinite_far = true;
  EXPECT_NO_THROW(validate(make_camera_params(inf)));
  PerspectiveCamera extreme;  // far/near = 1e8: x loses its 1 in float, as in Unity
  extreme.near_plane = 0.01f;
  extreme.far_plane = 1e6f;
  EXPECT_NO_THROW(validate(make_camera_params(extreme)));
  extreme.reversed_z = true;
  EXPECT_NO_THROW(validate(make_camera_params(extreme)));
}

// End to end: the inconsistent constants never reach a frame (scalar and OpenCL paths).
TEST_F(ValidateParams, NoPathFogsWithInconsistentConstants) {
  const TestFrame frame = make_test_frame(16, 9, true, ColorFormat::rgba32f);
  CameraParams p = frame.params;
  p.reversed_z = false;
  FogSettings settings;
  ColorImage out;
  EXPECT_MSG_HAS(error_of([&] { apply_fog_scalar(frame.color, frame.depth, out, p, settings); }), "reversed-Z values");
  if (runtime() == nullptr) GTEST_SKIP() << "no OpenCL device: " << runtime_error();
  EXPECT_MSG_HAS(error_of([&] { shared_pass().apply(frame.color, frame.depth, out, p, settings); }),
                 "reversed-Z values");
}

}  // namespace
}  // namespace fogcl::test
