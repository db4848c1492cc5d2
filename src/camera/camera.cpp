#include "fogcl/camera.h"

#include <algorithm>
#include <cmath>

#include "fogcl/error.h"
#include "runtime/format.h"

namespace fogcl {

namespace {
using detail::str;

// The one place the constants are computed from near and far (make_camera_params builds them,
// validate checks handed-in ones against them). Float arithmetic, as Unity's
// UnityShaderVariables / Camera.cpp (x loses its 1 once far/near >= 2^24; the kernel does not
// depend on x for conventional Z).
glm::vec4 zbuffer_params_for(Projection projection, float n, float f, bool reversed_z) {
  switch (projection) {
    case Projection::perspective_infinite_far:
      return glm::vec4(0.0f, 0.0f, 1.0f / n, 0.0f);  // eye depth = near / raw
    case Projection::orthographic: {
      // Eye depth = lerp(near, far, raw) (raw = 1 - raw with reversed Z), as Unity's
      // orthographic depth; Linear01Depth = eye / far.
      const float range = (f - n) / f;
      return reversed_z ? glm::vec4(-range, 1.0f, -(f - n), f) : glm::vec4(range, n / f, f - n, n);
    }
    case Projection::perspective:
      break;
  }
  if (reversed_z) {
    const float x = -1.0f + f / n;
    return glm::vec4(x, 1.0f, x / f, 1.0f / f);
  }
  const float y = f / n;
  const float x = 1.0f - y;
  return glm::vec4(x, y, x / f, y / f);
}

glm::vec4 projection_params_for(Projection projection, float n, float f) {
  return projection == Projection::perspective_infinite_far ? glm::vec4(1.0f, n, INFINITY, 0.0f)
                                                            : glm::vec4(1.0f, n, f, 1.0f / f);
}

// Handed-in constants agree with computed ones to this relative tolerance: far above float
// rounding (a user computing in double, Unity in float), far below any real inconsistency.
constexpr float kRelTol = 1e-4f;
bool close(float got, float want, float scale) { return std::fabs(got - want) <= kRelTol * scale; }

const char* projection_name(Projection p) {
  return p == Projection::orthographic ? "orthographic"
         : p == Projection::perspective_infinite_far ? "perspective infinite-far"
                                                     : "perspective";
}

// _ZBufferParams against near, far, the projection and the Z direction; `what` names the source
// of the values in the message.
void check_zbuffer_params(const glm::vec4& zb, Projection projection, float n, float f, bool reversed_z,
                          const std::string& what) {
  for (int c = 0; c < 4; ++c)
    if (!std::isfinite(zb[c]))
      throw Error(what + ": _ZBufferParams component " + std::to_string(c) + " is not finite (got " + str(zb[c]) + ")");
  const glm::vec4 e = zbuffer_params_for(projection, n, f, reversed_z);
  const float xy = std::max(std::fabs(e.x), std::fabs(e.y)), zw = std::max(std::fabs(e.z), std::fabs(e.w));
  if (close(zb.x, e.x, xy) && close(zb.y, e.y, xy) && close(zb.z, e.z, zw) && close(zb.w, e.w, zw)) return;
  const std::string z = reversed_z ? "reversed_z = true" : "reversed_z = false";
  std::string hint;
  if (projection != Projection::perspective_infinite_far) {
    const glm::vec4 other = zbuffer_params_for(projection, n, f, !reversed_z);
    const float oxy = std::max(std::fabs(other.x), std::fabs(other.y));
    if (close(zb.x, other.x, oxy) && close(zb.y, other.y, oxy))
      hint = reversed_z ? ": these are conventional-Z values (y = " + str(zb.y) + " != 1), set reversed_z = false"
                        : ": these are reversed-Z values (y = 1), set reversed_z = true";
  }
  throw Error(what + ": _ZBufferParams " + str(zb) + " do not match near " + str(n) + ", far " + str(f) + ", " +
              projection_name(projection) + ", " + z + " (expected " + str(e) +
              "; perspective: conventional (1 - far/near, far/near, x/far, y/far), reversed "
              "(far/near - 1, 1, x/far, 1/far))" + hint);
}
}  // namespace

void validate(const PerspectiveCamera& c) {
  if (!(c.near_plane > 0.0f) || !std::isfinite(c.near_plane))
    throw Error("camera near plane must be finite and > 0 (got " + str(c.near_plane) + ")");
  if (c.infinite_far && !c.reversed_z)
    throw Error("an infinite far plane needs reversed Z (conventional Z loses all depth precision there)");
  if (c.infinite_far) {
    // far is ignored; only the fov and aspect remain to check.
  } else if (!(c.far_plane > c.near_plane) || !std::isfinite(c.far_plane))
    throw Error("camera far plane must be finite and > near (got far " + str(c.far_plane) +
                ", near " + str(c.near_plane) + ")");
  if (!(c.fov_y_deg > 0.0f && c.fov_y_deg < 180.0f))
    throw Error("camera vertical fov must be in (0, 180) degrees (got " + str(c.fov_y_deg) + ")");
  if (!(c.aspect > 0.0f) || !std::isfinite(c.aspect))
    throw Error("camera aspect must be finite and > 0 (got " + str(c.aspect) + ")");
  if (!c.infinite_far && !std::isfinite(c.far_plane / c.near_plane))
    throw Error("camera far/near ratio overflows float (far " + str(c.far_plane) + ", near " +
                str(c.near_plane) + ")");
}

void validate(const OrthographicCamera& c) {
  if (!(c.ortho_size > 0.0f) || !std::isfinite(c.ortho_size))
    throw Error("orthographic size must be finite and > 0 (got " + str(c.ortho_size) + ")");
  if (!(c.near_plane >= 0.0f) || !std::isfinite(c.near_plane))
    throw Error("camera near plane must be finite and >= 0 (got " + str(c.near_plane) + ")");
  if (!(c.far_plane > c.near_plane) || !std::isfinite(c.far_plane))
    throw Error("camera far plane must be finite and > near (got far " + str(c.far_plane) +
                ", near " + str(c.near_plane) + ")");
  if (!(c.aspect > 0.0f) || !std::isfinite(c.aspect))
    throw Error("camera aspect must be finite and > 0 (got " + str(c.aspect) + ")");
}

CameraParams make_camera_params(const PerspectiveCamera& c) {
  validate(c);
  const float n = c.near_plane, f = c.far_plane;
  CameraParams p;
  p.reversed_z = c.reversed_z;
  const double tan_half = std::tan(double(c.fov_y_deg) * 0.5 * 3.14159265358979323846 / 180.0);
  const auto corners = [&](double z) {
    const double half_h = tan_half * z, half_w = half_h * double(c.aspect);
    p.frustum_corners[kBottomLeft] = glm::vec3(float(-half_w), float(-half_h), float(z));
    p.frustum_corners[kBottomRight] = glm::vec3(float(half_w), float(-half_h), float(z));
    p.frustum_corners[kTopLeft] = glm::vec3(float(-half_w), float(half_h), float(z));
    p.frustum_corners[kTopRight] = glm::vec3(float(half_w), float(half_h), float(z));
  };
  p.projection = c.infinite_far ? Projection::perspective_infinite_far : Projection::perspective;
  p.zbuffer_params = zbuffer_params_for(p.projection, n, f, c.reversed_z);
  p.projection_params = projection_params_for(p.projection, n, f);
  // Camera.CalculateFrustumCorners(rect 0..1, far): the far-plane rectangle in view space;
  // infinite far: normalised to view z = 1 so that distance = eye * |ray|.
  corners(c.infinite_far ? 1.0 : double(f));
  return p;
}

CameraParams make_camera_params(const OrthographicCamera& c) {
  validate(c);
  const float n = c.near_plane, f = c.far_plane;
  CameraParams p;
  p.projection = Projection::orthographic;
  p.reversed_z = c.reversed_z;
  p.zbuffer_params = zbuffer_params_for(p.projection, n, f, c.reversed_z);
  p.projection_params = projection_params_for(p.projection, n, f);
  const float half_h = c.ortho_size, half_w = c.ortho_size * c.aspect;
  p.frustum_corners[kBottomLeft] = glm::vec3(-half_w, -half_h, f);
  p.frustum_corners[kBottomRight] = glm::vec3(half_w, -half_h, f);
  p.frustum_corners[kTopLeft] = glm::vec3(-half_w, half_h, f);
  p.frustum_corners[kTopRight] = glm::vec3(half_w, half_h, f);
  return p;
}

PerspectiveCamera camera_from_projection(const glm::mat4& m, ClipDepth clip_depth) {
  // GLM is column-major: m[col][row]. A perspective projection has w_clip = ±z_view.
  const float w_from_z = m[2][3];
  if (m[3][3] != 0.0f || w_from_z == 0.0f || m[0][3] != 0.0f || m[1][3] != 0.0f)
    throw Error("projection matrix is not a perspective projection (orthographic cameras need "
                "the orthographic variant)");
  if (m[2][0] != 0.0f || m[2][1] != 0.0f || m[1][0] != 0.0f || m[0][1] != 0.0f ||
      m[3][0] != 0.0f || m[3][1] != 0.0f)
    throw Error("projection matrix is not a symmetric perspective (off-centre or skewed "
                "frustum): fogcl needs a centred frustum");
  if (!(m[1][1] > 0.0f) || !(m[0][0] > 0.0f))
    throw Error("projection matrix flips x or y (m[0][0] = " + str(m[0][0]) + ", m[1][1] = " +
                str(m[1][1]) + "): flip the image instead");
  // Forward = the view axis along which w_clip grows. Along it, at distance t:
  // ndc(t) = a + b / t with a = m[2][2] * sign, b = m[3][2] (w normalised to t).
  const double s = w_from_z > 0 ? 1.0 : -1.0;
  const double scale = std::fabs(double(w_from_z));
  const double a = double(m[2][2]) * s / scale;
  const double b = double(m[3][2]) / scale;
  if (b == 0.0)
    throw Error("projection matrix has an infinite near/far plane (m[3][2] == 0): not supported");
  // Conventional: ndc rises from e_near to e_far; b < 0. Reversed Z: it falls; b > 0.
  const bool reversed = b > 0.0;
  const double lo = clip_depth == ClipDepth::zero_to_one ? 0.0 : -1.0;
  const double e_near = reversed ? 1.0 : lo, e_far = reversed ? lo : 1.0;
  if (a == e_far)
    throw Error("projection matrix has an infinite far plane: needs the infinite-far variant");
  PerspectiveCamera c;
  c.reversed_z = reversed;
  c.near_plane = float(b / (e_near - a));
  c.far_plane = float(b / (e_far - a));
  c.fov_y_deg = float(2.0 * std::atan(1.0 / double(m[1][1])) * 180.0 / 3.14159265358979323846);
  c.aspect = float(double(m[1][1]) / double(m[0][0]));
  try {
    validate(c);
  } catch (const Error& e) {
    throw Error(std::string("projection matrix does not describe a valid camera: ") + e.what());
  }
  return c;
}

std::array<glm::vec3, 4> corners_from_unity_order(const std::array<glm::vec3, 4>& u) {
  // Unity: [0] bottom-left, [1] top-left, [2] top-right, [3] bottom-right.
  std::array<glm::vec3, 4> out;
  out[kBottomLeft] = u[0];
  out[kTopLeft] = u[1];
  out[kTopRight] = u[2];
  out[kBottomRight] = u[3];
  return out;
}

}  // namespace fogcl

namespace fogcl {
void validate(const CameraParams& p) {
  const float n = p.near_plane(), f = p.far_plane();
  const bool infinite = p.projection == Projection::perspective_infinite_far;
  const bool ortho = p.projection == Projection::orthographic;
  const glm::vec4& pp = p.projection_params;
  if (pp.x != 1.0f) {
    if (pp.x == -1.0f)
      throw Error("camera params: _ProjectionParams.x = -1 (Unity's flipped projection, rendering upside down into "
                  "a render texture) is not supported: fogcl's row 0 is the top of the view; flip the rows and pass "
                  "_ProjectionParams.x = 1");
    throw Error("camera params: _ProjectionParams.x must be 1 (got " + str(pp.x) + ")");
  }
  if (!(ortho ? n >= 0.0f : n > 0.0f) || !std::isfinite(n))
    throw Error(std::string("camera params: near (_ProjectionParams.y) must be finite and ") +
                (ortho ? ">= 0" : "> 0") + " (got " + str(n) + ")");
  if (infinite && !p.reversed_z) throw Error("camera params: an infinite far plane needs reversed Z");
  if (p.depth_kind != DepthKind::raw && p.depth_kind != DepthKind::eye && p.depth_kind != DepthKind::distance)
    throw Error("camera params: depth kind " + std::to_string(int(p.depth_kind)) + " is not one of raw, eye, distance");
  if (p.depth_kind == DepthKind::distance && ortho)
    throw Error("camera params: radial distance depth needs a perspective camera (an orthographic camera's rays are "
                "parallel: give eye or raw depth)");
  if (infinite ? f != INFINITY : !(f > n) || !std::isfinite(f) || (!ortho && !std::isfinite(f / n)))
    throw Error("camera params: far (_ProjectionParams.z) must be " +
                std::string(infinite ? "+inf for the infinite-far projection" : "finite and > near, far/near finite") +
                " (got far " + str(f) + ", near " + str(n) + ")");
  const float w = infinite ? 0.0f : 1.0f / f;
  if (!close(pp.w, w, w))
    throw Error("camera params: _ProjectionParams.w must be 1 / far = " + str(w) + " (got " + str(pp.w) + ")");
  check_zbuffer_params(p.zbuffer_params, p.projection, n, f, p.reversed_z, "camera params");

  const auto& c = p.frustum_corners;
  for (const glm::vec3& corner : c)
    for (int k = 0; k < 3; ++k)
      if (!std::isfinite(corner[k]))
        throw Error("camera params: frustum corner component is not finite (got " + str(corner[k]) + ")");
  const std::string got = " (got bottom-left " + str(c[kBottomLeft]) + ", bottom-right " + str(c[kBottomRight]) +
                          ", top-left " + str(c[kTopLeft]) + ", top-right " + str(c[kTopRight]) + ")";
  if (!(c[kBottomLeft].x < c[kBottomRight].x && c[kTopLeft].x < c[kTopRight].x &&
        c[kBottomLeft].y < c[kTopLeft].y && c[kBottomRight].y < c[kTopRight].y))
    throw Error("camera params: frustum corners are not in fogcl's order bottom-left, bottom-right, top-left, "
                "top-right (left x < right x, bottom y < top y)" + got +
                "; Unity's CalculateFrustumCorners order (bottom-left, top-left, top-right, bottom-right) needs "
                "corners_from_unity_order() or camera_params_from_unity()");
  float extent = 0.0f;
  for (const glm::vec3& corner : c) extent = std::max({extent, std::fabs(corner.x), std::fabs(corner.y)});
  if (!(close(c[kBottomLeft].x, c[kTopLeft].x, extent) && close(c[kBottomRight].x, c[kTopRight].x, extent) &&
        close(c[kBottomLeft].y, c[kBottomRight].y, extent) && close(c[kTopLeft].y, c[kTopRight].y, extent)))
    throw Error("camera params: frustum corners do not form a rectangle (left corners share x, bottom corners "
                "share y, ...)" + got);
  const float plane = infinite ? 1.0f : f;
  for (int k = 0; k < 4; ++k)
    if (!close(c[k].z, plane, plane))
      throw Error("camera params: frustum corner " + std::to_string(k) + " has z = " + str(c[k].z) + " but " +
                  (infinite ? std::string("infinite-far corners are normalised to z = 1")
                            : "the corners lie on the far plane, z = far = " + str(f) +
                                  " (CalculateFrustumCorners with farClipPlane)") + got);
}

CameraParams camera_params_from_unity(const UnityCameraConstants& u) {
  const std::string what = "Unity camera constants";
  const float w = u.ortho_params.w;
  if (w != 0.0f && w != 1.0f)
    throw Error(what + ": unity_OrthoParams.w must be 0 (perspective) or 1 (orthographic) (got " + str(w) + ")");
  const float n = u.projection_params.y, f = u.projection_params.z;
  if (!std::isfinite(f))
    throw Error(what + ": _ProjectionParams.z (far) = " + str(f) + ": Unity cameras have a finite far plane (for "
                "fogcl's infinite-far variant use make_camera_params on a PerspectiveCamera with infinite_far)");
  const auto& uc = u.frustum_corners;  // bottom-left, top-left, top-right, bottom-right
  if (!(uc[0].x < uc[3].x && uc[1].x < uc[2].x && uc[0].y < uc[1].y && uc[3].y < uc[2].y))
    throw Error(what + ": frustum_corners are not in Unity's CalculateFrustumCorners order bottom-left, top-left, "
                "top-right, bottom-right (got " + str(uc[0]) + ", " + str(uc[1]) + ", " + str(uc[2]) + ", " +
                str(uc[3]) + "); corners already in fogcl's order go straight into CameraParams");
  CameraParams p;
  p.projection_params = u.projection_params;
  p.frustum_corners = corners_from_unity_order(uc);
  // Unity: reversed (far/near - 1, 1, ...), conventional (1 - far/near, far/near, ...), and
  // far > near, so y == 1 exactly says reversed.
  p.reversed_z = u.zbuffer_params.y == 1.0f;
  p.projection = w == 1.0f ? Projection::orthographic : Projection::perspective;
  if (p.projection == Projection::perspective) {
    p.zbuffer_params = u.zbuffer_params;
  } else {
    // Unity computes _ZBufferParams from near and far as for a perspective camera; they carry the
    // Z direction only. fogcl's orthographic variant takes its linear constants.
    if (n > 0.0f) check_zbuffer_params(u.zbuffer_params, Projection::perspective, n, f, p.reversed_z, what);
    p.zbuffer_params = zbuffer_params_for(Projection::orthographic, n, f, p.reversed_z);
    for (const glm::vec3& corner : uc)
      if (!close(std::fabs(corner.x), u.ortho_params.x, u.ortho_params.x) ||
          !close(std::fabs(corner.y), u.ortho_params.y, u.ortho_params.y))
        throw Error(what + ": orthographic frustum corner " + str(corner) +
                    " does not lie at unity_OrthoParams' half extents (+-" + str(u.ortho_params.x) + ", +-" +
                    str(u.ortho_params.y) + ")");
  }
  validate(p);
  return p;
}
double frustum_aspect(const CameraParams& p) {
  const auto& c = p.frustum_corners;
  return (double(c[kBottomRight].x) - double(c[kBottomLeft].x)) / (double(c[kTopLeft].y) - double(c[kBottomLeft].y));
}

void validate(const CameraParams& p, int width, int height) {
  validate(p);
  if (p.non_square_pixels || width < 1 || height < 1) return;  // sizes are the frame checks' to report
  const double camera = frustum_aspect(p), frame = double(width) / double(height);
  const double tolerance = std::max(1e-3, 0.5 / width + 0.5 / height);
  if (std::fabs(camera / frame - 1.0) <= tolerance) return;
  std::string hint;
  if (std::fabs(camera * frame - 1.0) <= tolerance) hint = " (width and height swapped?)";
  throw Error("camera aspect " + str(float(camera)) + " does not match the " + std::to_string(width) + "x" +
              std::to_string(height) + " frame's " + str(float(frame)) + hint +
              ": make the camera with aspect = width / height, or set CameraParams::non_square_pixels when the "
              "frustum is meant to differ");
}

}  // namespace fogcl
