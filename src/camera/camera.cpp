#include "fogcl/camera.h"

#include <cmath>
#include <sstream>

#include "fogcl/error.h"

namespace fogcl {

namespace {
template <class T>
std::string str(T v) {
  std::ostringstream s;
  s.precision(9);
  s << v;
  return s.str();
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
  if (c.infinite_far) {
    // Eye depth = near / raw; the rays are normalised to view z = 1 so that distance = eye * |ray|.
    p.projection = Projection::perspective_infinite_far;
    p.zbuffer_params = glm::vec4(0.0f, 0.0f, 1.0f / n, 0.0f);
    p.projection_params = glm::vec4(1.0f, n, INFINITY, 0.0f);
    corners(1.0);
    return p;
  }
  // UnityShaderVariables / Camera.cpp: float arithmetic, as Unity does (x loses its 1 once
  // far/near >= 2^24; the kernel does not depend on x for conventional Z).
  if (c.reversed_z) {
    const float x = -1.0f + f / n;
    p.zbuffer_params = glm::vec4(x, 1.0f, x / f, 1.0f / f);
  } else {
    const float y = f / n;
    const float x = 1.0f - y;
    p.zbuffer_params = glm::vec4(x, y, x / f, y / f);
  }
  p.projection_params = glm::vec4(1.0f, n, f, 1.0f / f);
  // Camera.CalculateFrustumCorners(rect 0..1, far): the far-plane rectangle in view space.
  corners(double(f));
  return p;
}

CameraParams make_camera_params(const OrthographicCamera& c) {
  validate(c);
  const float n = c.near_plane, f = c.far_plane;
  CameraParams p;
  p.projection = Projection::orthographic;
  p.reversed_z = c.reversed_z;
  // Eye depth = lerp(near, far, raw) (raw = 1 - raw with reversed Z), as Unity's orthographic
  // depth; Linear01Depth = eye / far.
  const float range = (f - n) / f;
  p.zbuffer_params = c.reversed_z ? glm::vec4(-range, 1.0f, -(f - n), f) : glm::vec4(range, n / f, f - n, n);
  p.projection_params = glm::vec4(1.0f, n, f, 1.0f / f);
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
  if (!(n > 0.0f) || !std::isfinite(n))
    throw Error("camera params: near (_ProjectionParams.y) must be finite and > 0 (got " + str(n) + ")");
  const bool infinite = p.projection == Projection::perspective_infinite_far;
  if (infinite && !p.reversed_z)
    throw Error("camera params: an infinite far plane needs reversed Z");
  if (!(f > n) || (!infinite && !std::isfinite(f)))
    throw Error("camera params: far (_ProjectionParams.z) must be finite and > near (got " + str(f) + ")");
  for (int c = 0; c < 4; ++c)
    if (!std::isfinite(p.zbuffer_params[c]))
      throw Error("camera params: _ZBufferParams component " + std::to_string(c) + " is not finite (got " +
                  str(p.zbuffer_params[c]) + ")");
  // Linear01Depth must be positive over the whole depth range [0, 1]. Perspective, conventional:
  // y = far/near >= 1 (x is not used: fog_math.h evaluates y (1 - raw) + raw); reversed: y > 0 and
  // x + y > 0. Orthographic: x * raw + y >= 0 (its near plane may be at 0).
  const float zx = p.zbuffer_params.x, zy = p.zbuffer_params.y;
  const bool ok = p.projection == Projection::orthographic ? zy >= 0.0f && zx + zy >= 0.0f
                  : p.projection == Projection::perspective_infinite_far ? p.zbuffer_params.z > 0.0f
                  : p.reversed_z ? zy > 0.0f && zx + zy > 0.0f
                                 : zy >= 1.0f;
  if (!ok)
    throw Error("camera params: _ZBufferParams (" + str(zx) + ", " + str(zy) +
                ") do not describe a perspective depth range (need y > 0 and x + y > 0)");
  for (const glm::vec3& c : p.frustum_corners)
    for (int k = 0; k < 3; ++k)
      if (!std::isfinite(c[k]))
        throw Error("camera params: frustum corner component is not finite (got " + str(c[k]) + ")");
}
}  // namespace fogcl
