// The renderer's camera (fogcl/renderer_camera.h): a camera-to-world matrix in each renderer's axes
// and lens data give the rays the renderer itself casts, in fogcl's world; Blender's own numbers
// (captured from Blender 3.4) as the reference for its lens rules and camera; bad matrices are
// refused naming the rule; OpenEXR's worldToCamera / worldToNDC give the pose; world-space inputs
// (volume centres, light matrix) are converted with the camera.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <Imath/ImathMatrix.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStandardAttributes.h>
#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "fogcl/exr_io.h"
#include "fogcl/renderer_camera.h"
#include "test_support.h"
#include "volume/volume_params.h"
#include "volume_common.h"

namespace fogcl::test {
namespace {

constexpr double kPi = 3.14159265358979323846;
const Axes kAllAxes[] = {Axes::unity, Axes::blender, Axes::houdini, Axes::maya};

// The renderer's world -> fogcl's, written out here from each renderer's documentation (not from
// axes_to_fogcl): Unity is fogcl's world; Blender's +z (up) is fogcl's +y and its +y (the front
// view's direction) fogcl's +z; Houdini's and Maya's -z (where a default camera looks) is fogcl's +z.
glm::dvec3 to_fogcl_by_hand(Axes axes, const glm::dvec3& p) {
  switch (axes) {
    case Axes::unity:
      return p;
    case Axes::blender:
      return {p.x, p.z, p.y};
    case Axes::houdini:
    case Axes::maya:
      return {p.x, p.y, -p.z};
  }
  return p;
}

// Where a default camera looks in its own local axes.
double local_view_z(Axes axes) { return axes == Axes::unity ? 1.0 : -1.0; }

// The 16 numbers a renderer prints for a camera-to-world transform with rotation columns R and
// translation t: row by row, column-vector layout for unity and blender, row-vector (the
// transpose) for houdini and maya. Values as float32, as the renderers store them.
std::array<double, 16> printed(Axes axes, const glm::dmat3& r, const glm::dvec3& t) {
  double m[4][4] = {};  // m[row][column], column vectors
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col) m[row][col] = double(float(r[col][row]));
    m[row][3] = double(float(t[row]));
  }
  m[3][3] = 1.0;
  const bool row_vectors = axes == Axes::houdini || axes == Axes::maya;
  std::array<double, 16> out{};
  for (int row = 0; row < 4; ++row)
    for (int col = 0; col < 4; ++col) out[std::size_t(4 * row + col)] = row_vectors ? m[col][row] : m[row][col];
  return out;
}

glm::dmat3 rotation(double ax_deg, double ay_deg, double az_deg) {
  const glm::dmat4 r = glm::rotate(glm::dmat4(1.0), az_deg * kPi / 180.0, glm::dvec3(0, 0, 1)) *
                       glm::rotate(glm::dmat4(1.0), ay_deg * kPi / 180.0, glm::dvec3(0, 1, 0)) *
                       glm::rotate(glm::dmat4(1.0), ax_deg * kPi / 180.0, glm::dvec3(1, 0, 0));
  return glm::dmat3(r);
}

// fogcl's ray through image point (u, v) (u from the left, v from the bottom, in [0, 1]) in world
// space, as the volume pass gets it: the packed frame's camera rotation times the bilinear corner
// ray (docs/volumetric.md, "World and rays").
struct FogclRays {
  std::array<float, VOL_F_COUNT> frame{};
  glm::dvec3 at(double u, double v) const {
    const auto c = [&](int k) {
      return glm::dvec3(frame[std::size_t(VOL_F_CORNERS + 3 * k)], frame[std::size_t(VOL_F_CORNERS + 3 * k + 1)],
                        frame[std::size_t(VOL_F_CORNERS + 3 * k + 2)]);
    };
    const glm::dvec3 view = (1 - v) * ((1 - u) * c(kBottomLeft) + u * c(kBottomRight)) +
                            v * ((1 - u) * c(kTopLeft) + u * c(kTopRight));
    const auto col = [&](int at) {
      return glm::dvec3(frame[std::size_t(at)], frame[std::size_t(at + 1)], frame[std::size_t(at + 2)]);
    };
    return col(VOL_F_RIGHT) * view.x + col(VOL_F_UP) * view.y + col(VOL_F_FORWARD) * view.z;
  }
  glm::dvec3 eye() const {
    return glm::dvec3(frame[VOL_F_EYE], frame[VOL_F_EYE + 1], frame[VOL_F_EYE + 2]);
  }
};

FogclRays fogcl_rays(const CameraPose& pose, float fov_y_deg, float aspect) {
  PerspectiveCamera cam;
  cam.fov_y_deg = fov_y_deg;
  cam.aspect = aspect;
  cam.near_plane = 0.1f;
  cam.far_plane = 500.0f;
  VolumeScene scene;
  scene.pose = pose;
  const detail::PackedVolumeFrame packed =
      detail::pack_volume_frame(64, 36, make_camera_params(cam), scene, VolumeSettings{}, ColorFormat::rgba32f, nullptr,
                                0, 0, 500.0f);
  FogclRays r;
  r.frame = packed.frame;
  return r;
}

// The angle [rad] between two directions (|cross| of the unit vectors; +inf when they point apart).
double angle(const glm::dvec3& a, const glm::dvec3& b) {
  const glm::dvec3 x = glm::normalize(a), y = glm::normalize(b);
  if (glm::dot(x, y) <= 0.0) return INFINITY;
  return glm::length(glm::cross(x, y));
}

TEST(RendererCamera, AxesMapTheRenderersWorldsAsDocumented) {
  const glm::vec3 probes[] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0.3f, -2.5f, 7.25f}};
  for (Axes axes : kAllAxes) {
    const glm::mat3 a = axes_to_fogcl(axes);
    for (const glm::vec3& p : probes) {  // A is exact: 0 and +-1
      const glm::dvec3 got(a * p), want = to_fogcl_by_hand(axes, glm::dvec3(p));
      EXPECT_EQ(got, want) << to_string(axes) << ": (" << got.x << ", " << got.y << ", " << got.z << ") want ("
                           << want.x << ", " << want.y << ", " << want.z << ")";
    }
    // A right-handed world needs a reflection: determinant -1; unity is fogcl's world.
    EXPECT_EQ(glm::determinant(a), right_handed(axes) ? -1.0f : 1.0f) << to_string(axes);
    EXPECT_EQ(parse_axes(to_string(axes)), axes);
  }
  // Up is up: Blender's +z and Houdini's / Maya's +y are fogcl's +y.
  EXPECT_EQ(axes_to_fogcl(Axes::blender) * glm::vec3(0, 0, 1), glm::vec3(0, 1, 0));
  EXPECT_EQ(axes_to_fogcl(Axes::houdini) * glm::vec3(0, 1, 0), glm::vec3(0, 1, 0));
  EXPECT_MSG_HAS(error_of([] { parse_axes("z-up"); }), "got 'z-up'");
}

// For each renderer, a camera written by hand both ways: as the renderer prints its
// camera-to-world matrix, and as fogcl's --eye/--forward/--up in fogcl's world. The frames the
// volume pass gets must be the same floats.
TEST(RendererCamera, MatrixAndAxesGiveTheSameRaysAsEyeForwardUpFov) {
  struct Case {
    Axes axes;
    std::array<double, 16> printed;  // as the renderer prints it
    CameraPose fogcl;                // the same camera as fogcl's flags
  };
  const Case cases[] = {
      // Unity: at (1, 2, 3), turned 90 degrees about +y: looks along +x (localToWorldMatrix,
      // column vectors: its columns are the local axes).
      {Axes::unity, {0, 0, 1, 1, 0, 1, 0, 2, -1, 0, 0, 3, 0, 0, 0, 1}, {{1, 2, 3}, {1, 0, 0}, {0, 1, 0}}},
      // Blender: at (1, 2, 3), turned 90 degrees about +x: its local -z looks along world +y (the
      // front view), its local +y is world +z. fogcl: eye (1, 3, 2), looking along +z, +y up.
      {Axes::blender, {1, 0, 0, 1, 0, 0, -1, 2, 0, 1, 0, 3, 0, 0, 0, 1}, {{1, 3, 2}, {0, 0, 1}, {0, 1, 0}}},
      // Houdini: at (1, 2, 3), turned 90 degrees about +y: its local -z looks along world -x.
      // Row vectors: the rows are the local axes, then the translation.
      {Axes::houdini, {0, 0, -1, 0, 0, 1, 0, 0, 1, 0, 0, 0, 1, 2, 3, 1}, {{1, 2, -3}, {-1, 0, 0}, {0, 1, 0}}},
      // Maya: at (0, 5, 10), looking down 90 degrees (turned -90 about +x): local -z is world -y,
      // local +y is world -z. fogcl: eye (0, 5, -10), forward (0, -1, 0), up (0, 0, 1).
      {Axes::maya, {1, 0, 0, 0, 0, 0, -1, 0, 0, 1, 0, 0, 0, 5, 10, 1}, {{0, 5, -10}, {0, -1, 0}, {0, 0, 1}}},
  };
  for (const Case& c : cases) {
    for (const float aspect : {16.0f / 9.0f, 0.6f}) {
      RendererCamera rc;
      rc.camera_to_world = camera_to_world_from_rows(c.printed, c.axes);
      rc.axes = c.axes;
      rc.fov_y_deg = 47.5f;
      const FogclCamera got = to_fogcl_camera(rc, aspect);
      EXPECT_EQ(got.fov_y_deg, 47.5f);
      const FogclRays from_matrix = fogcl_rays(got.pose, got.fov_y_deg, aspect);
      const FogclRays from_flags = fogcl_rays(c.fogcl, 47.5f, aspect);
      int differing = 0;
      for (int k = VOL_F_EYE; k < VOL_F_CORNERS + 12; ++k) differing += from_matrix.frame[k] != from_flags.frame[k];
      std::printf("[ measured ] %s, aspect %.3f: %d of %d camera floats differ from --eye/--forward/--up\n",
                  to_string(c.axes), double(aspect), differing, VOL_F_CORNERS + 12);
      EXPECT_EQ(differing, 0) << to_string(c.axes);
    }
  }
}

// A rotated camera (no axis-aligned shortcut) in each renderer's world: fogcl's world rays for a
// grid of image points against the renderer's own rays (its camera convention, its matrix), mapped
// into fogcl's world by hand. Landscape and portrait frames, lens data and a fov.
TEST(RendererCamera, RotatedCameraGivesTheRenderersRaysInEveryAxes) {
  const glm::dmat3 r = rotation(71.0, 8.0, 27.0) * rotation(0.0, 0.0, -13.0);
  const glm::dvec3 t(3.5, -7.25, 2.75);
  double worst = 0.0, worst_eye = 0.0;
  for (Axes axes : kAllAxes)
    for (const double aspect : {640.0 / 360.0, 360.0 / 640.0}) {
      RendererCamera rc;
      rc.camera_to_world = camera_to_world_from_rows(printed(axes, r, t), axes);
      rc.axes = axes;
      Lens lens;
      lens.focal_length_mm = 35.0f;
      lens.sensor_width_mm = 36.0f;
      rc.lens = lens;
      const FogclCamera cam = to_fogcl_camera(rc, float(aspect));
      const FogclRays rays = fogcl_rays(cam.pose, cam.fov_y_deg, float(aspect));
      // The renderer's rays: Blender's AUTO fit puts the 36 mm across the larger dimension.
      const double tan_long = 36.0 / (2.0 * 35.0);
      const double tan_h = aspect >= 1 ? tan_long : tan_long * aspect, tan_v = aspect >= 1 ? tan_long / aspect : tan_long;
      worst_eye = std::max(worst_eye, glm::length(rays.eye() - to_fogcl_by_hand(axes, t)));
      for (double u = 0.0; u <= 1.0; u += 0.25)
        for (double v = 0.0; v <= 1.0; v += 0.25) {
          const glm::dvec3 local((2 * u - 1) * tan_h, (2 * v - 1) * tan_v, local_view_z(axes));
          const glm::dvec3 want = to_fogcl_by_hand(axes, r * local);
          const double e = angle(rays.at(u, v), want);
          worst = std::max(worst, e);
          EXPECT_LE(e, 2e-6) << to_string(axes) << " aspect " << aspect << " (u, v) = " << u << ", " << v;
        }
    }
  std::printf("[ worst    ] rotated camera, 4 axes x 2 aspects x 25 rays: angle %.2e rad, eye %.2e\n", worst, worst_eye);
  EXPECT_LE(worst_eye, 1e-6);
}

// Captured from Blender 3.4.1 (Debian's): a camera at (3.5, -7.25, 2.75), rotation_euler (71, 8,
// 27) degrees, object scale 1.5 (which Blender and Cycles ignore); matrix_world without the scale
// (examples/blender_camera.py prints it so) and Camera.view_frame(scene) corners rotated into the
// world (top-right, bottom-right, bottom-left, top-left), for each resolution and sensor setting.
struct BlenderCapture {
  int width, height;
  const char* fit;
  float lens, sensor_width, sensor_height;
  std::array<std::array<double, 3>, 4> corners;  // TR, BR, BL, TL directions from the eye
};
const std::array<double, 16> kBlenderMatrixWorld = {0.882335305, -0.0305566378, 0.469628245, 3.5,
                                                    0.449572295, 0.349824309,   -0.821892738, -7.25,
                                                    -0.13917309, 0.936316848,   0.322399765,  2.75,
                                                    0,           0,             0,            1};
const BlenderCapture kBlender[] = {
    {640, 360, "auto", 35, 36, 24,
     {{{-0.0240094252, 1.12223661, -0.11969164},
       {-0.00682131574, 0.925460458, -0.646369815},
       {-0.88915664, 0.475888133, -0.507196784},
       {-0.906344712, 0.672664285, 0.0194814503}}}},
    {360, 640, "auto", 35, 36, 24,
     {{{-0.223704547, 1.10041678, 0.115571797},
       {-0.193147898, 0.750592411, -0.820745051},
       {-0.689461529, 0.497708023, -0.742460191},
       {-0.720018148, 0.847532332, 0.193856657}}}},
    {360, 640, "horizontal", 35, 36, 24,
     {{{-0.0425768271, 1.33480346, 0.449250907},
       {0.0117460862, 0.712893546, -1.21531236},
       {-0.870589197, 0.26332128, -1.07613933},
       {-0.924912155, 0.885231197, 0.588423967}}}},
    {640, 360, "vertical", 50, 36, 24,
     {{{-0.209372386, 2.28680849, -0.327217132},
       {-0.178815737, 1.93698406, -1.26353395},
       {-1.74741185, 1.13774443, -1.01611519},
       {-1.77796853, 1.48756886, -0.0797983035}}}},
    {480, 480, "auto", 28, 23.76f, 15.6f,
     {{{-0.127544627, 1.36825871, 0.0186395049},
       {-0.0969879851, 1.01843441, -0.917677343},
       {-0.979323268, 0.56886214, -0.778504252},
       {-1.00987995, 0.91868645, 0.157812595}}}},
    {360, 640, "vertical", 50, 36, 24,
     {{{-0.745513618, 2.01363087, -0.242650151},
       {-0.714956999, 1.66380656, -1.178967},
       {-1.21127057, 1.41092205, -1.10068214},
       {-1.24182725, 1.76074636, -0.164365292}}}},
};

// Blender's frame corners, as the lens flags and the matrix give them to fogcl: the four corner
// rays of the volume pass against Blender's (mapped into fogcl's world by hand), and the vertical
// fov against Blender's (from its corners) for every sensor fit, landscape, portrait and square.
TEST(RendererCamera, BlenderLensAndMatrixGiveBlendersViewFrame) {
  double worst_ray = 0.0, worst_fov = 0.0;
  for (const BlenderCapture& b : kBlender) {
    RendererCamera rc;
    rc.camera_to_world = camera_to_world_from_rows(kBlenderMatrixWorld, Axes::blender);
    rc.axes = Axes::blender;
    Lens lens;
    lens.focal_length_mm = b.lens;
    lens.sensor_width_mm = b.sensor_width;
    lens.sensor_height_mm = b.sensor_height;
    lens.fit = parse_sensor_fit(b.fit);
    rc.lens = lens;
    const float aspect = float(b.width) / float(b.height);
    const FogclCamera cam = to_fogcl_camera(rc, aspect);
    const FogclRays rays = fogcl_rays(cam.pose, cam.fov_y_deg, aspect);
    // Blender's corners: top-right, bottom-right, bottom-left, top-left.
    const double uv[4][2] = {{1, 1}, {1, 0}, {0, 0}, {0, 1}};
    for (int k = 0; k < 4; ++k) {
      const glm::dvec3 blender(b.corners[k][0], b.corners[k][1], b.corners[k][2]);
      const double e = angle(rays.at(uv[k][0], uv[k][1]), to_fogcl_by_hand(Axes::blender, blender));
      worst_ray = std::max(worst_ray, e);
      EXPECT_LE(e, 2e-6) << b.width << "x" << b.height << " " << b.fit << " corner " << k;
    }
    // Blender's vertical fov: the angle between its top and bottom corner rays at the centre line.
    const glm::dvec3 top = 0.5 * (glm::dvec3(b.corners[0][0], b.corners[0][1], b.corners[0][2]) +
                                  glm::dvec3(b.corners[3][0], b.corners[3][1], b.corners[3][2]));
    const glm::dvec3 bottom = 0.5 * (glm::dvec3(b.corners[1][0], b.corners[1][1], b.corners[1][2]) +
                                     glm::dvec3(b.corners[2][0], b.corners[2][1], b.corners[2][2]));
    const double blender_fov = std::acos(glm::dot(glm::normalize(top), glm::normalize(bottom))) * 180.0 / kPi;
    const double fov_err = std::fabs(vertical_fov_deg(lens, aspect) - blender_fov);
    worst_fov = std::max(worst_fov, fov_err);
    std::printf("[ measured ] Blender %dx%d %-10s %2.0f mm on %.2f x %.2f mm: fov_y %.6f deg (Blender %.6f)\n", b.width,
                b.height, b.fit, double(b.lens), double(b.sensor_width), double(b.sensor_height),
                vertical_fov_deg(lens, aspect), blender_fov);
    EXPECT_LE(fov_err, 1e-4) << b.width << "x" << b.height << " " << b.fit;
  }
  std::printf("[ worst    ] Blender view frames: corner ray angle %.2e rad, vertical fov %.2e deg\n", worst_ray, worst_fov);
}

// Blender's rules by case, with the numbers a reader can check by hand: the portrait frame under
// auto fit reads the sensor width vertically, horizontal fit keeps it horizontal, vertical fit
// reads the sensor height.
TEST(RendererCamera, LensFovPerSensorFitIncludingPortrait) {
  const auto fov = [](SensorFit fit, double aspect) {
    Lens l;
    l.focal_length_mm = 50.0f;
    l.sensor_width_mm = 36.0f;
    l.sensor_height_mm = 24.0f;
    l.fit = fit;
    return vertical_fov_deg(l, aspect);
  };
  const auto deg = [](double tan_half) { return 2.0 * std::atan(tan_half) * 180.0 / kPi; };
  const struct {
    SensorFit fit;
    double aspect, want;
  } cases[] = {
      {SensorFit::automatic, 16.0 / 9.0, deg(0.36 * 9.0 / 16.0)},   // landscape: width across
      {SensorFit::automatic, 1.0, deg(0.36)},                       // square: horizontal (>=)
      {SensorFit::automatic, 9.0 / 16.0, deg(0.36)},                // portrait: the width spans the height
      {SensorFit::horizontal, 9.0 / 16.0, deg(0.36 * 16.0 / 9.0)},  // portrait, width across
      {SensorFit::horizontal, 16.0 / 9.0, deg(0.36 * 9.0 / 16.0)},
      {SensorFit::vertical, 16.0 / 9.0, deg(0.24)},  // the height spans the height
      {SensorFit::vertical, 9.0 / 16.0, deg(0.24)},
  };
  for (const auto& c : cases) {
    const double got = fov(c.fit, c.aspect);
    std::printf("[ measured ] %-10s aspect %.4f: fov_y %.9f deg (want %.9f)\n", to_string(c.fit), c.aspect, got, c.want);
    EXPECT_NEAR(got, c.want, 1e-9) << to_string(c.fit) << " " << c.aspect;
  }
  // Auto never reads the sensor height (Blender's BKE_camera_sensor_size).
  Lens l;
  l.sensor_height_mm = 1.0f;
  EXPECT_EQ(vertical_fov_deg(l, 0.5), vertical_fov_deg(Lens{}, 0.5));
  l.focal_length_mm = 0.0f;
  EXPECT_MSG_HAS(error_of([&] { vertical_fov_deg(l, 1.0); }), "focal length [mm] must be finite and > 0 (got 0)");
  EXPECT_MSG_HAS(error_of([] { vertical_fov_deg(Lens{}, 0.0); }), "aspect");
  EXPECT_MSG_HAS(error_of([] { parse_sensor_fit("diagonal"); }), "got 'diagonal'");
}

TEST(RendererCamera, BadMatricesAreRefusedNamingTheRule) {
  const std::array<double, 16> identity{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  const auto refused = [](std::array<double, 16> m, Axes axes) {
    return error_of([&] { camera_frame(camera_to_world_from_rows(m, axes), axes); });
  };
  const auto with = [&](int k, double v) {
    std::array<double, 16> m = identity;
    m[std::size_t(k)] = v;
    return m;
  };
  const struct {
    const char* what;
    std::array<double, 16> m;
    Axes axes;
    std::vector<std::string> expect;
  } cases[] = {
      {"scale", with(0, 1.5), Axes::blender, {"not rigid", "column 0", "length 1.5", "scale"}},
      {"small scale", with(5, 1.001), Axes::unity, {"not rigid", "column 1", "1.00100005", "within 0.0001"}},
      {"shear", with(1, 0.01), Axes::unity, {"not rigid"}},
      {"shear, unit columns", {1, 0.0099995, 0, 0, 0, 0.99995, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}, Axes::unity,
       {"not orthogonal", "shear"}},
      {"reflection", with(10, -1.0), Axes::unity, {"determinant -1", "reflection", "Camera.cameraToWorldMatrix"}},
      {"mirror in blender", with(0, -1.0), Axes::blender, {"determinant -1", "reflection"}},
      {"NaN", with(7, NAN), Axes::blender, {"element m13", "not finite", "nan"}},
      {"infinite", with(3, INFINITY), Axes::unity, {"element m03", "not finite"}},
      {"projective last row", with(14, 0.5), Axes::blender, {"last row must be 0 0 0 1", "0 0 0.5 1"}},
      {"row-vector matrix as blender", with(12, 4.0), Axes::blender,
       {"column-vector", "last row must be 0 0 0 1", "translation in the last row", "transpose"}},
      {"column-vector matrix as houdini", with(3, 4.0), Axes::houdini,
       {"row-vector", "last column must be 0 0 0 1", "translation in the last column", "transpose"}},
      {"projective last column in maya", with(11, 0.5), Axes::maya, {"last column must be 0 0 0 1"}},
  };
  for (const auto& c : cases) {
    const std::string msg = refused(c.m, c.axes);
    std::printf("[ message  ] %s: %s\n", c.what, msg.c_str());
    for (const std::string& part : c.expect) EXPECT_MSG_HAS(msg, part);
  }
  // And accepted: a rigid matrix printed with 7 digits (1e-7 off orthonormal) in every axes.
  const std::array<double, 16> rows = printed(Axes::blender, rotation(33, -71, 12), {1, 2, 3});
  EXPECT_NO_THROW(camera_frame(camera_to_world_from_rows(rows, Axes::blender), Axes::blender));
  // The library's own check on a GLM matrix, whatever the layout it came from.
  glm::mat4 projective(1.0f);
  projective[2][3] = -1.0f;
  EXPECT_MSG_HAS(error_of([&] { camera_frame(projective, Axes::unity); }), "last row must be 0 0 0 1");
  // A frame whose handedness is not the axes': a right-handed frame given as unity.
  CameraFrame f;
  f.forward = glm::vec3(0, 0, -1);
  EXPECT_MSG_HAS(error_of([&] { camera_pose(f, Axes::unity); }), "right-handed world, but axes unity is left-handed");
  EXPECT_NO_THROW(camera_pose(f, Axes::houdini));
}

// An EXR with worldToCamera / worldToNDC: OpenEXR's camera space (left-handed, +z forward) and,
// as some renderers write it, a right-handed camera space looking down -z; a left-handed world
// and a right-handed (Houdini's) one.
void write_camera_exr(const std::string& path, const Imath::M44d& w2c, const Imath::M44d& w2n) {
  const int w = 8, h = 4;
  Imf::Header header(w, h);
  for (const char* c : {"R", "G", "B", "A", "Z"}) header.channels().insert(c, Imf::Channel(Imf::FLOAT));
  Imath::M44f w2c_f, w2n_f;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      w2c_f[i][j] = float(w2c[i][j]);
      w2n_f[i][j] = float(w2n[i][j]);
    }
  Imf::addWorldToCamera(header, w2c_f);
  Imf::addWorldToNDC(header, w2n_f);
  std::vector<float> pixels(std::size_t(w * h), 1.0f);
  Imf::OutputFile file(path.c_str(), header);
  Imf::FrameBuffer fb;
  for (const char* c : {"R", "G", "B", "A", "Z"})
    fb.insert(c, Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(pixels.data()), sizeof(float), sizeof(float) * w));
  file.setFrameBuffer(fb);
  file.writePixels(h);
}

// Row-vector (Imath) matrices of a camera: camera -> NDC for a camera space looking along
// view_z (+1: OpenEXR's, -1: a right-handed camera space), vertical fov and aspect.
Imath::M44d camera_to_ndc(double view_z, double fov_deg, double aspect) {
  const double tan_v = std::tan(fov_deg * kPi / 360.0), tan_h = tan_v * aspect;
  Imath::M44d c2n(0.0);
  // depth d = view_z * z: ndc_x = 0.5 + 0.5 x / (d tan_h), ndc_y = 0.5 - 0.5 y / (d tan_v), w = d.
  c2n[0][0] = 0.5 / tan_h;
  c2n[2][0] = 0.5 * view_z;
  c2n[1][1] = -0.5 / tan_v;
  c2n[2][1] = 0.5 * view_z;
  c2n[2][2] = view_z;
  c2n[3][2] = -0.1;
  c2n[2][3] = view_z;
  return c2n;
}

TEST(RendererCamera, ExrWorldToCameraGivesThePose) {
  const std::string dir = fresh_dir("renderer-camera");
  const glm::dmat3 r = rotation(-20.0, 35.0, 10.0);
  const glm::dvec3 t(4.0, 1.5, -6.0);
  const double fov = 40.0, aspect = 2.0;  // the file is 8x4
  // The same camera as a Houdini matrix (row vectors, camera looks along local -z).
  RendererCamera houdini;
  houdini.camera_to_world = camera_to_world_from_rows(printed(Axes::houdini, r, t), Axes::houdini);
  houdini.axes = Axes::houdini;
  const CameraPose want = to_fogcl_camera(houdini, float(aspect)).pose;
  // Houdini's world -> its camera (column vectors: R^T (p - t)), as Imath row vectors.
  // Row vectors: p_local = p_world * M with M = R (R[i][j]: the world-i component of local axis j,
  // GLM's r[j][i]) and the last row -t R. The camera looks along its local -z.
  Imath::M44d w2c_local;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) w2c_local[i][j] = double(float(r[j][i]));
  for (int j = 0; j < 3; ++j) w2c_local[3][j] = -(double(float(t.x)) * w2c_local[0][j] +
                                                  double(float(t.y)) * w2c_local[1][j] +
                                                  double(float(t.z)) * w2c_local[2][j]);
  Imath::M44d flip;  // OpenEXR's camera space: z toward the view
  flip[2][2] = -1.0;
  const Imath::M44d w2c_exr = w2c_local * flip;
  const struct {
    const char* what;
    Imath::M44d w2c, w2n;
  } files[] = {
      {"OpenEXR's camera space (+z forward)", w2c_exr, w2c_exr * camera_to_ndc(1.0, fov, aspect)},
      {"a -z camera space", w2c_local, w2c_local * camera_to_ndc(-1.0, fov, aspect)},
  };
  for (const auto& f : files) {
    const std::string path = dir + "/camera.exr";
    write_camera_exr(path, f.w2c, f.w2n);
    const ExrInput in = read_exr(path, ExrReadRequest{});
    ASSERT_TRUE(in.camera.present) << f.what << ": " << in.camera.note;
    ASSERT_TRUE(in.camera.pose_present) << f.what << ": " << in.camera.pose_note;
    EXPECT_NEAR(in.camera.fov_y_deg, fov, 1e-4) << f.what;
    EXPECT_NEAR(in.camera.aspect, aspect, 1e-5) << f.what;
    const CameraPose got = camera_pose(in.camera.frame, Axes::houdini);
    const double e = std::max({glm::length(glm::dvec3(got.eye - want.eye)),
                               glm::length(glm::dvec3(glm::normalize(got.forward) - glm::normalize(want.forward))),
                               glm::length(glm::dvec3(glm::normalize(got.up) - glm::normalize(want.up)))});
    std::printf("[ measured ] %s, Houdini's world: pose off the --camera-to-world one by %.2e\n", f.what, e);
    EXPECT_LE(e, 2e-6) << f.what;
    // A right-handed world is refused as fogcl's own (no --axes), naming the rule.
    EXPECT_MSG_HAS(error_of([&] { camera_pose(in.camera.frame, Axes::unity); }),
                   "right-handed world, but axes unity is left-handed");
  }
  // A left-handed world (RenderMan's, Unity's): worldToCamera is a rotation (determinant +1) and
  // the frame is taken as it is.
  Imath::M44d w2c_left;
  w2c_left.setAxisAngle(Imath::V3d(0, 1, 0), kPi / 6);
  w2c_left[3][0] = 2.5;
  w2c_left[3][1] = -1.0;
  w2c_left[3][2] = 4.0;
  write_camera_exr(dir + "/left.exr", w2c_left, w2c_left * camera_to_ndc(1.0, fov, aspect));
  const ExrInput left = read_exr(dir + "/left.exr", ExrReadRequest{});
  ASSERT_TRUE(left.camera.pose_present) << left.camera.pose_note;
  const CameraPose p = camera_pose(left.camera.frame, Axes::unity);
  const Imath::M44d c2w = w2c_left.inverse();
  EXPECT_LE(glm::length(glm::dvec3(p.eye) - glm::dvec3(c2w[3][0], c2w[3][1], c2w[3][2])), 1e-5);
  EXPECT_LE(glm::length(glm::dvec3(p.forward) - glm::dvec3(c2w[2][0], c2w[2][1], c2w[2][2])), 1e-6);
  EXPECT_LE(glm::length(glm::dvec3(p.up) - glm::dvec3(c2w[1][0], c2w[1][1], c2w[1][2])), 1e-6);
  // A scaled worldToCamera (other units in camera space) has no pose, and says why.
  Imath::M44d scaled = w2c_left;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 4; ++j) scaled[i][j] *= 100.0;
  write_camera_exr(dir + "/scaled.exr", scaled, scaled * camera_to_ndc(1.0, fov, aspect));
  const ExrInput s = read_exr(dir + "/scaled.exr", ExrReadRequest{});
  EXPECT_TRUE(s.camera.present);
  EXPECT_FALSE(s.camera.pose_present);
  EXPECT_MSG_HAS(s.camera.pose_note, "not rigid");
}

// Volume centres, noise scroll and tilings, light directions and shadow matrices in the renderer's
// world become fogcl's with the camera: a point's position relative to the camera and to the
// light's clip space is the same in both worlds.
TEST(RendererCamera, WorldInputsConvertWithTheCamera) {
  for (Axes axes : kAllAxes) {
    FogVolume v;
    v.center = glm::vec3(1.0f, -2.0f, 3.5f);
    v.speed = glm::vec3(0.25f, 0.5f, -1.0f);
    v.tiling = glm::vec3(0.1f, 0.2f, 0.3f);
    v.detail_tiling = glm::vec3(1.0f, 2.0f, 3.0f);
    v.max_y = 7.0f;
    const FogVolume f = volume_to_fogcl(axes, v);
    EXPECT_EQ(glm::dvec3(f.center), to_fogcl_by_hand(axes, glm::dvec3(v.center))) << to_string(axes);
    EXPECT_EQ(glm::dvec3(f.speed), to_fogcl_by_hand(axes, glm::dvec3(v.speed))) << to_string(axes);
    EXPECT_EQ(glm::dvec3(f.tiling), glm::abs(to_fogcl_by_hand(axes, glm::dvec3(v.tiling)))) << to_string(axes);
    EXPECT_EQ(glm::dvec3(f.detail_tiling), glm::abs(to_fogcl_by_hand(axes, glm::dvec3(v.detail_tiling))));
    EXPECT_EQ(f.max_y, 7.0f);  // a height along up: the same in both worlds
    // A light's world -> clip matrix: the same clip position for the same point.
    const glm::mat4 light = glm::perspective(0.8f, 1.0f, 0.5f, 50.0f) *
                            glm::lookAt(glm::vec3(5, 8, -3), glm::vec3(0, 0, 0), glm::vec3(0, 1, 0));
    const glm::mat4 converted = world_matrix_to_fogcl(axes, light);
    double worst = 0.0;
    for (const glm::vec3 p : {glm::vec3(0.5f, 1.0f, -0.25f), glm::vec3(-3, 2, 7)}) {
      const glm::vec4 a = light * glm::vec4(p, 1.0f);
      const glm::vec4 b = converted * glm::vec4(glm::vec3(to_fogcl_by_hand(axes, glm::dvec3(p))), 1.0f);
      worst = std::max(worst, double(glm::length(a - b) / glm::length(a)));
    }
    std::printf("[ measured ] %s: light clip position, relative difference %.2e\n", to_string(axes), worst);
    EXPECT_LE(worst, 1e-6) << to_string(axes);
  }
}

}  // namespace
}  // namespace fogcl::test
