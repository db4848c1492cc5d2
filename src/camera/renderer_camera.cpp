#include "fogcl/renderer_camera.h"

#include <cmath>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>

#include "fogcl/error.h"
#include "runtime/format.h"

namespace fogcl {

namespace {

using detail::str;

constexpr double kPi = 3.14159265358979323846;
// A rigid matrix's 3x3 part: columns of unit length and pairwise orthogonal to this much. Far
// above float rounding of a printed rotation (1e-7), far below any scale or shear a renderer would
// apply on purpose (a camera scaled by 1.01 is refused).
constexpr double kRigidTol = 1e-4;
// The last row (column-vector layout) is 0 0 0 1 to this much: printed exactly by every renderer.
constexpr double kRowTol = 1e-6;

bool finite(const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// "" when the three vectors are unit length and pairwise orthogonal within kRigidTol, else what
// is wrong, naming them by `names`.
std::string orthonormal_problem(const glm::dvec3 (&v)[3], const char* const (&names)[3]) {
  for (int i = 0; i < 3; ++i) {
    const double len = glm::length(v[i]);
    if (!(std::fabs(len - 1.0) <= kRigidTol))
      return std::string(names[i]) + " " + str(v[i]) + " has length " + str(len) +
             " (a scale or shear): it must be 1 within " + str(kRigidTol);
  }
  for (int i = 0; i < 3; ++i)
    for (int j = i + 1; j < 3; ++j) {
      const double d = glm::dot(v[i], v[j]);
      if (!(std::fabs(d) <= kRigidTol))
        return std::string(names[i]) + " and " + names[j] + " are not orthogonal (dot product " + str(d) +
               ", a shear): it must be 0 within " + str(kRigidTol);
    }
  return "";
}

}  // namespace

const char* to_string(Axes axes) {
  switch (axes) {
    case Axes::unity:
      return "unity";
    case Axes::blender:
      return "blender";
    case Axes::houdini:
      return "houdini";
    case Axes::maya:
      return "maya";
  }
  return "?";
}

Axes parse_axes(const std::string& text) {
  for (Axes a : {Axes::unity, Axes::blender, Axes::houdini, Axes::maya})
    if (text == to_string(a)) return a;
  throw Error("axes must be unity (left-handed, +y up), blender (right-handed, +z up), houdini or maya "
              "(right-handed, +y up) (got '" + text + "')");
}

bool right_handed(Axes axes) { return axes != Axes::unity; }

glm::mat3 axes_to_fogcl(Axes axes) {
  // GLM: m[column][row]; fogcl = A * renderer.
  glm::mat3 a(1.0f);
  switch (axes) {
    case Axes::unity:
      break;
    case Axes::blender:  // (x, y, z) -> (x, z, y): Blender's up (+z) becomes +y, its +y (front) +z
      a = glm::mat3(glm::vec3(1, 0, 0), glm::vec3(0, 0, 1), glm::vec3(0, 1, 0));
      break;
    case Axes::houdini:
    case Axes::maya:  // (x, y, z) -> (x, y, -z): a camera's local -z becomes fogcl's +z
      a = glm::mat3(glm::vec3(1, 0, 0), glm::vec3(0, 1, 0), glm::vec3(0, 0, -1));
      break;
  }
  return a;
}

glm::vec3 scale_to_fogcl(Axes axes, const glm::vec3& scale) {
  const glm::mat3 a = axes_to_fogcl(axes);
  glm::vec3 out(0.0f);
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r)
      if (a[c][r] != 0.0f) out[r] = scale[c];
  return out;
}

glm::mat4 world_matrix_to_fogcl(Axes axes, const glm::mat4& world_to_x) {
  // x = W * p_renderer = W * A^T * p_fogcl (A orthogonal). A's entries are 0 and +-1: exact.
  return world_to_x * glm::mat4(glm::transpose(axes_to_fogcl(axes)));
}

FogVolume volume_to_fogcl(Axes axes, const FogVolume& v) {
  const glm::mat3 a = axes_to_fogcl(axes);
  FogVolume out = v;
  out.center = a * v.center;
  out.speed = a * v.speed;
  out.tiling = scale_to_fogcl(axes, v.tiling);
  out.detail_tiling = scale_to_fogcl(axes, v.detail_tiling);
  return out;
}

glm::mat4 camera_to_world_from_rows(const std::array<double, 16>& rows, Axes axes) {
  for (int k = 0; k < 16; ++k)
    if (!std::isfinite(rows[std::size_t(k)]))
      throw Error("camera-to-world matrix element m" + std::to_string(k / 4) + std::to_string(k % 4) +
                  " is not finite (got " + str(rows[std::size_t(k)]) + ")");
  const auto at = [&](int r, int c) { return rows[std::size_t(4 * r + c)]; };
  const auto is_0001 = [&](double a, double b, double c, double d) {
    return std::fabs(a) <= kRowTol && std::fabs(b) <= kRowTol && std::fabs(c) <= kRowTol &&
           std::fabs(d - 1.0) <= kRowTol;
  };
  const bool last_row = is_0001(at(3, 0), at(3, 1), at(3, 2), at(3, 3));
  const bool last_column = is_0001(at(0, 3), at(1, 3), at(2, 3), at(3, 3));
  const bool row_vectors = axes == Axes::houdini || axes == Axes::maya;
  const std::string got = " (got last row " + str(at(3, 0)) + " " + str(at(3, 1)) + " " + str(at(3, 2)) + " " +
                          str(at(3, 3)) + ", last column " + str(at(0, 3)) + " " + str(at(1, 3)) + " " +
                          str(at(2, 3)) + " " + str(at(3, 3)) + ")";
  if (!row_vectors && !last_row)
    throw Error(std::string("camera-to-world matrix: ") + to_string(axes) +
                " matrices are column-vector matrices (translation in the last column): the last row must be "
                "0 0 0 1" + got +
                (last_column ? "; this one has its translation in the last row, a row-vector matrix: give its "
                               "transpose"
                             : ""));
  if (row_vectors && !last_column)
    throw Error(std::string("camera-to-world matrix: ") + to_string(axes) +
                " matrices are row-vector matrices (translation in the last row): the last column must be "
                "0 0 0 1" + got +
                (last_row ? "; this one has its translation in the last column, a column-vector matrix: give its "
                            "transpose"
                          : ""));
  glm::mat4 m(1.0f);
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) m[c][r] = float(row_vectors ? at(c, r) : at(r, c));  // GLM: m[column][row]
  return m;
}

CameraFrame camera_frame(const glm::mat4& m, Axes axes) {
  const std::string what = "camera-to-world matrix: ";
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(m[c][r]))
        throw Error(what + "element (row " + std::to_string(r) + ", column " + std::to_string(c) +
                    ") is not finite (got " + str(m[c][r]) + ")");
  if (!(std::fabs(m[0][3]) <= kRowTol && std::fabs(m[1][3]) <= kRowTol && std::fabs(m[2][3]) <= kRowTol &&
        std::fabs(m[3][3] - 1.0) <= kRowTol))
    throw Error(what + "the last row must be 0 0 0 1 (an affine transform; got " + str(m[0][3]) + " " +
                str(m[1][3]) + " " + str(m[2][3]) + " " + str(m[3][3]) + ")");
  const glm::dvec3 cols[3] = {glm::dvec3(m[0]), glm::dvec3(m[1]), glm::dvec3(m[2])};
  const std::string problem = orthonormal_problem(cols, {"column 0 (local x)", "column 1 (local y)", "column 2 (local z)"});
  if (!problem.empty())
    throw Error(what + "not rigid: " + problem + " (rotation and translation only; clear the camera's scale)");
  const double det = glm::determinant(glm::dmat3(cols[0], cols[1], cols[2]));
  if (!(det > 0.0))
    throw Error(what + "its rotation part has determinant " + str(det) + ": a reflection, not a rotation (" +
                (axes == Axes::unity ? "Unity's Camera.cameraToWorldMatrix flips z for OpenGL's view space: give "
                                       "transform.localToWorldMatrix; "
                                     : "") +
                "a mirrored camera's negative scale must be cleared)");
  CameraFrame f;
  f.eye = glm::vec3(m[3]);
  f.right = glm::vec3(glm::normalize(cols[0]));
  f.up = glm::vec3(glm::normalize(cols[1]));
  // unity: the camera looks along its local +z; blender, houdini, maya along its local -z.
  f.forward = glm::vec3(glm::normalize(axes == Axes::unity ? cols[2] : -cols[2]));
  return f;
}

CameraPose camera_pose(const CameraFrame& f, Axes axes) {
  const glm::dvec3 v[3] = {glm::dvec3(f.right), glm::dvec3(f.up), glm::dvec3(f.forward)};
  if (!finite(glm::dvec3(f.eye))) throw Error("camera frame: eye is not finite (got " + str(glm::dvec3(f.eye)) + ")");
  for (const glm::dvec3& x : v)
    if (!finite(x)) throw Error("camera frame: a direction is not finite (got " + str(x) + ")");
  const std::string problem = orthonormal_problem(v, {"right", "up", "forward"});
  if (!problem.empty()) throw Error("camera frame: " + problem);
  // cross(right, up) is +forward when the coordinates are left-handed (Unity: x, y, z = right, up,
  // forward), -forward when right-handed.
  const double handedness = glm::dot(glm::cross(v[0], v[1]), v[2]);
  const bool frame_right_handed = handedness < 0.0;
  if (frame_right_handed != right_handed(axes))
    throw Error(std::string("camera frame: right x up = ") + (frame_right_handed ? "-forward" : "+forward") +
                " (right " + str(v[0]) + ", up " + str(v[1]) + ", forward " + str(v[2]) + "): a " +
                (frame_right_handed ? "right" : "left") + "-handed world, but axes " + to_string(axes) + " is " +
                (right_handed(axes) ? "right" : "left") + "-handed");
  const glm::mat3 a = axes_to_fogcl(axes);
  CameraPose p;
  p.eye = a * f.eye;
  p.forward = a * f.forward;
  p.up = a * f.up;
  return p;
}

const char* to_string(SensorFit fit) {
  switch (fit) {
    case SensorFit::automatic:
      return "auto";
    case SensorFit::horizontal:
      return "horizontal";
    case SensorFit::vertical:
      return "vertical";
  }
  return "?";
}

SensorFit parse_sensor_fit(const std::string& text) {
  for (SensorFit f : {SensorFit::automatic, SensorFit::horizontal, SensorFit::vertical})
    if (text == to_string(f)) return f;
  throw Error("sensor fit must be auto, horizontal or vertical (got '" + text + "')");
}

void validate(const Lens& l) {
  const auto positive = [](const char* name, float v) {
    if (!(std::isfinite(v) && v > 0.0f))
      throw Error(std::string("lens: ") + name + " must be finite and > 0 (got " + str(v) + ")");
  };
  positive("focal length [mm]", l.focal_length_mm);
  positive("sensor width [mm]", l.sensor_width_mm);
  positive("sensor height [mm]", l.sensor_height_mm);
}

double vertical_fov_deg(const Lens& l, double aspect) {
  validate(l);
  if (!(std::isfinite(aspect) && aspect > 0.0))
    throw Error("lens: the image aspect (width / height) must be finite and > 0 (got " + str(aspect) + ")");
  const double f = l.focal_length_mm;
  double tan_half;
  switch (l.fit) {
    case SensorFit::vertical:
      tan_half = double(l.sensor_height_mm) / (2.0 * f);
      break;
    case SensorFit::horizontal:
      tan_half = double(l.sensor_width_mm) / (2.0 * f) / aspect;
      break;
    case SensorFit::automatic:
    default:
      // BKE_camera_sensor_fit: width >= height fits horizontally; BKE_camera_sensor_size: the
      // sensor width either way (AUTO never reads sensor_y).
      tan_half = double(l.sensor_width_mm) / (2.0 * f) / (aspect >= 1.0 ? aspect : 1.0);
      break;
  }
  return 2.0 * std::atan(tan_half) * 180.0 / kPi;
}

FogclCamera to_fogcl_camera(const RendererCamera& c, float aspect) {
  if (!(std::isfinite(aspect) && aspect > 0.0f))
    throw Error("renderer camera: the image aspect (width / height) must be finite and > 0 (got " + str(aspect) + ")");
  FogclCamera out;
  out.pose = camera_pose(camera_frame(c.camera_to_world, c.axes), c.axes);
  const double fov = c.lens ? vertical_fov_deg(*c.lens, aspect) : double(c.fov_y_deg);
  if (!(fov > 0.0 && fov < 180.0) || !(float(fov) > 0.0f))
    throw Error("renderer camera: the vertical field of view must be in (0, 180) degrees (got " + str(fov) + ")");
  out.fov_y_deg = float(fov);
  return out;
}

}  // namespace fogcl
