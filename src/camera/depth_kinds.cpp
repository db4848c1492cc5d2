#include "fogcl/depth_kinds.h"

#include <cmath>

#include "fogcl/error.h"
#include "pass/formulas.h"

namespace fogcl {

// The pixel's uv and its far-plane ray, as the fog pass computes them.
namespace depth_math = formulas;

const char* to_string(DepthKind kind) {
  switch (kind) {
    case DepthKind::raw: return "raw";
    case DepthKind::eye: return "eye";
    case DepthKind::distance: return "distance";
  }
  return "?";
}

DepthKind parse_depth_kind(const std::string& text) {
  for (DepthKind k : {DepthKind::raw, DepthKind::eye, DepthKind::distance})
    if (text == to_string(k)) return k;
  throw Error("depth kind must be raw, eye or distance (got '" + text + "')");
}

float sky_raw_depth(const CameraParams& camera) { return camera.reversed_z ? 0.0f : 1.0f; }

double raw_from_eye_depth(double eye, const CameraParams& camera) {
  const double far_plane = double(camera.far_plane()), x = double(camera.zbuffer_params.x),
               y = double(camera.zbuffer_params.y);
  if (!std::isfinite(eye) || eye <= 0.0 || eye >= far_plane) return double(sky_raw_depth(camera));
  double raw = 0.0;
  switch (camera.projection) {
    case Projection::perspective: raw = (far_plane / eye - y) / x; break;
    case Projection::perspective_infinite_far: raw = double(camera.near_plane()) / eye; break;
    case Projection::orthographic: raw = (eye / far_plane - y) / x; break;
  }
  return std::fmin(std::fmax(raw, 0.0), 1.0);  // nearer than the near plane: the near plane
}

namespace {

// Calls convert(depth sample, eye depth in double) for every pixel of linear depth `kind`.
template <class Convert>
void for_each_eye_depth(DepthImage& depth, DepthKind kind, const CameraParams& camera, Convert&& convert) {
  validate(camera);
  if (kind == DepthKind::distance && camera.projection == Projection::orthographic)
    throw Error("depth kind distance needs a perspective camera (an orthographic camera's rays are parallel: give "
                "eye or raw depth)");
  // The far-plane rays' view z: far, or 1 with an infinite far plane (their corners are normalised).
  const double ray_z = camera.projection == Projection::perspective_infinite_far ? 1.0 : double(camera.far_plane());
  const int w = depth.width(), h = depth.height();
  const auto& c = camera.frustum_corners;
  const double inv_width = 1.0 / double(w);
  for (int y = 0; y < h; ++y) {
    const double v = depth_math::fog_pixel_v<double>(y, h);
    for (int x = 0; x < w; ++x) {
      float& d = depth.at(x, y);
      double eye = double(d);
      if (kind == DepthKind::distance) {
        const double length =
            depth_math::fog_corner_ray_term(c, depth_math::fog_pixel_u<double>(x, inv_width), v, /*squared=*/0);
        eye = eye * ray_z / length;  // non-finite / <= 0 stay so, and become sky below
      }
      convert(d, eye);
    }
  }
}

}  // namespace

void to_raw_depth(DepthImage& depth, DepthKind kind, const CameraParams& camera) {
  if (kind == DepthKind::raw) return;
  for_each_eye_depth(depth, kind, camera, [&](float& d, double eye) { d = float(raw_from_eye_depth(eye, camera)); });
}

void to_eye_depth(DepthImage& depth, DepthKind kind, const CameraParams& camera) {
  if (kind != DepthKind::distance) return;
  for_each_eye_depth(depth, kind, camera, [](float& d, double eye) { d = float(eye); });
}

}  // namespace fogcl
