// Camera -> the constants a Unity shader sees (docs/DESIGN.md §1, §2): _ZBufferParams,
// _ProjectionParams and the four far-plane frustum-corner rays.
#pragma once

#include <array>
#include <optional>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace fogcl {

// A symmetric perspective camera. View space: camera at the origin looking along +z, +y up
// (Unity's camera space for CalculateFrustumCorners).
struct PerspectiveCamera {
  float fov_y_deg = 60.0f;         // vertical field of view [degrees], in (0, 180); Unity default 60
  float aspect = 16.0f / 9.0f;     // width / height, finite and > 0
  float near_plane = 0.3f;         // [world units], finite and > 0; Unity default 0.3
  float far_plane = 1000.0f;       // [world units], finite and > near_plane; Unity default 1000
  bool reversed_z = false;         // depth 1 at near, 0 at far (D3D11+/Metal/Vulkan Unity)
  // Reversed Z with the far plane at infinity (needs reversed_z; far_plane is then ignored):
  // raw depth = near / eye depth, 0 is infinitely far. A variant of its own (Projection).
  bool infinite_far = false;
};

// An orthographic camera (Unity's Camera.orthographic). Depth is linear in eye depth.
struct OrthographicCamera {
  float ortho_size = 5.0f;         // Unity's orthographicSize: half the vertical extent [world units], > 0
  float aspect = 16.0f / 9.0f;     // width / height, finite and > 0
  float near_plane = 0.3f;         // [world units], finite and >= 0
  float far_plane = 1000.0f;       // [world units], finite and > near_plane
  bool reversed_z = false;         // depth 1 at near, 0 at far
};

// How raw depth maps to distance; each is its own kernel variant (docs/DESIGN.md §2.2).
enum class Projection {
  perspective,               // Linear01Depth = 1 / (x * raw + y)
  perspective_infinite_far,  // reversed Z, far at infinity: eye depth = near / raw; raw 0 is sky
  orthographic,              // Linear01Depth = x * raw + y (linear); rays are parallel
};

// What the depth buffer holds; linear kinds are kernel variants of their own and reach the formulas
// as they are, never through raw depth (docs/accuracy.md, "Linear depth").
enum class DepthKind {
  raw,       // raw device depth in [0, 1] (the depth buffer's value)
  eye,       // linear eye depth along the view axis [world units] (Unity's LinearEyeDepth, EXR Z)
  distance,  // radial distance from the eye [world units] (|view-space position|); perspective only
};

// Where the camera is (docs/volumetric.md §World and rays): Unity's world
// space, left-handed, +y up. View space maps to world by the rotation with columns (right, up',
// forward), right = normalize(cross(up, forward)), up' = cross(forward, right).
struct CameraPose {
  glm::vec3 eye{0.0f};                  // [world], finite
  glm::vec3 forward{0.0f, 0.0f, 1.0f};  // view direction, non-zero (normalised by fogcl)
  glm::vec3 up{0.0f, 1.0f, 0.0f};       // non-zero, not parallel to forward
};

// Corner order used by fogcl: bottom-left, bottom-right, top-left, top-right (index u + 2v).
enum Corner { kBottomLeft = 0, kBottomRight = 1, kTopLeft = 2, kTopRight = 3 };

struct CameraParams {
  // _ZBufferParams. Perspective, conventional Z: (1 - f/n, f/n, x/f, y/f); reversed Z:
  // (-1 + f/n, 1, x/f, 1/f). Orthographic: Linear01Depth = x * raw + y, conventional
  // ((f - n)/f, n/f, ., .), reversed (-(f - n)/f, 1, ., .); z, w give eye depth the same way.
  // Infinite far: (0, 0, 1/n, 0) (Linear01Depth does not exist; the kernel uses near / raw).
  glm::vec4 zbuffer_params{0.0f};
  // _ProjectionParams: (1, near, far, 1/far); infinite far: (1, near, +inf, 0).
  glm::vec4 projection_params{0.0f};
  // Corner rays in view space, in Corner order: perspective at z = far; infinite far normalised
  // to z = 1; orthographic the corners of the far-plane rectangle (rays are parallel to +z).
  std::array<glm::vec3, 4> frustum_corners{};
  bool reversed_z = false;
  Projection projection = Projection::perspective;
  // What the depth buffer holds. Linear depth: values nearer than near are the near plane, values
  // from 0.9999 far on (and +inf, NaN, <= 0) are sky, as raw depth's clamp and sky test make them.
  DepthKind depth_kind = DepthKind::raw;
  // The camera's pose in the world (eye, view -> world rotation): needed by the passes that work
  // in world space, the deferred pass's height fog (FogMode::height, docs/DESIGN.md §6) among
  // them; the other modes ignore it. The volume pass takes its pose from VolumeScene::pose.
  std::optional<CameraPose> pose;
  // The frustum's aspect (corner width / height) differs from the frame's width / height on
  // purpose (non-square pixels, an anamorphic squeeze): the passes then skip that check
  // (validate(params, width, height)). Default false: a mismatch, such as a 16:9 camera on a
  // square frame or width and height swapped, is an error.
  bool non_square_pixels = false;

  float near_plane() const { return projection_params.y; }
  float far_plane() const { return projection_params.z; }
};

// Throws fogcl::Error naming the value and the rule for an invalid camera.
void validate(const PerspectiveCamera& camera);
void validate(const OrthographicCamera& camera);

// The constants exactly as Unity computes them (float arithmetic for _ZBufferParams).
CameraParams make_camera_params(const PerspectiveCamera& camera);
CameraParams make_camera_params(const OrthographicCamera& camera);

// How a projection matrix maps view depth to clip-space z: OpenGL / GLM default (-1..1) or
// D3D / Vulkan / GLM_FORCE_DEPTH_ZERO_TO_ONE (0..1). The depth buffer holds [0, 1] either way.
enum class ClipDepth { negative_one_to_one, zero_to_one };

// Recovers the camera from a GLM (column-major) projection matrix, right- or left-handed,
// conventional or reversed Z. Throws fogcl::Error for orthographic, asymmetric (off-centre),
// y-flipped or infinite-far projections, which have no PerspectiveCamera.
PerspectiveCamera camera_from_projection(const glm::mat4& projection,
                                         ClipDepth clip_depth = ClipDepth::negative_one_to_one);

// Unity's Camera.CalculateFrustumCorners returns bottom-left, top-left, top-right, bottom-right;
// this returns them in fogcl's Corner order.
std::array<glm::vec3, 4> corners_from_unity_order(const std::array<glm::vec3, 4>& unity_corners);

}  // namespace fogcl

namespace fogcl {
// Checks constants handed in directly (integration API) against each other, so that no
// combination gives a silently unfogged or wrongly fogged frame (docs/DESIGN.md §2.1). Throws
// fogcl::Error naming the value and the rule when
//  - a value is not finite, near <= 0 (orthographic: < 0) or far <= near (far is +inf exactly
//    for the infinite-far projection);
//  - _ProjectionParams.x != 1 (-1 is Unity's flipped projection: flip the rows instead) or
//    _ProjectionParams.w != 1 / far;
//  - _ZBufferParams do not match near, far, `projection` and `reversed_z` (relative 1e-4): e.g.
//    reversed-Z values (y = 1) with reversed_z = false, or conventional ones with reversed_z true;
//  - the corners are not in fogcl's Corner order (left x < right x, bottom y < top y; Unity's
//    order BL, TL, TR, BR fails this), not a rectangle, or not at the far plane (z = far;
//    infinite far: z = 1).
void validate(const CameraParams& params);
// The same, and the frame the constants are used on: unless params.non_square_pixels, the
// frustum's aspect (the corners' width / height) must be the frame's width / height within the
// larger of relative 1e-3 and half a pixel of each side's rounding (0.5 / width + 0.5 / height
// relative), else fogcl::Error naming both aspects. Every pass checks this for each frame.
void validate(const CameraParams& params, int width, int height);
// The frustum's aspect: the corner rays' width over their height.
double frustum_aspect(const CameraParams& params);

// The constants as a Unity renderer has them, under Unity's names.
struct UnityCameraConstants {
  glm::vec4 zbuffer_params{0.0f};     // _ZBufferParams
  glm::vec4 projection_params{0.0f};  // _ProjectionParams: (1, near, far, 1 / far)
  // Camera.CalculateFrustumCorners(new Rect(0, 0, 1, 1), camera.farClipPlane, ...): view space,
  // in Unity's order bottom-left, top-left, top-right, bottom-right, at z = far.
  std::array<glm::vec3, 4> frustum_corners{};
  // unity_OrthoParams: (half width = orthographicSize * aspect, half height = orthographicSize,
  // unused, w = 1 orthographic / 0 perspective). All zero (the default) means perspective.
  glm::vec4 ortho_params{0.0f};
};

// CameraParams from Unity's constants: the corners are reordered, reversed Z is read from
// _ZBufferParams (y == 1: reversed; y == far / near: conventional) and the projection from
// unity_OrthoParams.w. For orthographic cameras, Unity's _ZBufferParams (computed from near and
// far as for perspective) only give the Z direction; fogcl's linear ones are derived, and the
// corners must span unity_OrthoParams' half extents. The result is validated as above; every
// inconsistency throws fogcl::Error naming the value and the rule. Unity has no infinite far
// plane: use make_camera_params on a PerspectiveCamera with infinite_far for that variant.
CameraParams camera_params_from_unity(const UnityCameraConstants& unity);
}  // namespace fogcl
