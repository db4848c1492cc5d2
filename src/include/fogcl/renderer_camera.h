// A renderer's camera as fogcl's: the pose from a camera-to-world matrix in the renderer's axes,
// the vertical field of view from lens data as renderers state it, and the conversion of every
// other world-space input (volume centres, light direction, shadow matrix) from the renderer's
// world into fogcl's.
//
// fogcl's world is Unity's: left-handed, +x right, +y up, +z forward (docs/volumetric.md, "World
// and rays"). A renderer's world is mapped into it by a signed permutation A that keeps "up" up:
//
//   --axes   world                        a camera object looks  matrix as printed       A: (x, y, z) ->
//   unity    left-handed, +y up           along local +z, +y up  column vectors          (x, y, z)
//   blender  right-handed, +z up          along local -z, +y up  column vectors          (x, z, y)
//   houdini  right-handed, +y up          along local -z, +y up  row vectors             (x, y, -z)
//   maya     right-handed, +y up          along local -z, +y up  row vectors             (x, y, -z)
//
// - unity: Transform.localToWorldMatrix of the camera's transform (Matrix4x4, column vectors: the
//   translation is m03, m13, m23). Camera.cameraToWorldMatrix is not that matrix: Unity builds it
//   for OpenGL's view space, which looks along -z, so it carries a reflection (determinant -1) and
//   is refused as one.
// - blender: Object.matrix_world of the camera object (mathutils, column vectors: the translation
//   is the last column). The world's front view looks along +y, which A makes fogcl's +z: Blender's
//   front view is Unity's default view. Cycles ignores a camera's scale; fogcl refuses it (the
//   matrix must be rigid): examples/blender_camera.py prints the matrix without it.
// - houdini: the camera object's world transform (hou.Matrix4, row vectors: p' = p * M, the
//   translation is the last row). Houdini's world is right-handed, +y up; a camera looks along its
//   local -z with +y up.
// - maya: the camera transform's world matrix (MMatrix, `xform -q -ws -m`; row vectors, the
//   translation in the last row). Right-handed, +y up; a camera looks along its local -z.
// A right-handed world needs a reflection to become left-handed: A has determinant -1 there, and
// it is the same for positions and directions. max_y (a volume's height fade) is a height along
// the renderer's up axis, which A maps to fogcl's +y: it needs no conversion.
//
// OpenEXR's worldToCamera (ImfStandardAttributes.h) maps the world into a left-handed camera space
// (+x right, +y up, +z the viewing direction, as Pixar's RenderMan), with Imath's row vectors:
// p_camera = p_world * worldToCamera. The world itself is the renderer's; a right-handed world
// makes worldToCamera's determinant negative. fogcl reads the camera's position and its image
// right, up and viewing directions in that world (the directions as worldToNDC places them on the
// image), then converts them with the axes like any other pose (camera_pose below).
#pragma once

#include <array>
#include <optional>
#include <string>

#include <glm/mat3x3.hpp>
#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include "fogcl/volumes.h"

namespace fogcl {

// A renderer's world axes and camera convention (the table above).
enum class Axes { unity, blender, houdini, maya };

const char* to_string(Axes axes);
// "unity", "blender", "houdini" or "maya"; throws fogcl::Error naming the value otherwise.
Axes parse_axes(const std::string& text);
// blender, houdini and maya; unity is left-handed, like fogcl.
bool right_handed(Axes axes);

// A: the renderer's world -> fogcl's, for points and directions alike (an orthogonal signed
// permutation, so its inverse is its transpose).
glm::mat3 axes_to_fogcl(Axes axes);
// A per-axis scale (a noise tiling) in fogcl's axes: A without its signs.
glm::vec3 scale_to_fogcl(Axes axes, const glm::vec3& scale);
// A world -> X matrix (column vectors, e.g. a light's world -> clip) that takes the renderer's world
// points, re-expressed for fogcl's: world_to_x * [transpose(A) 0; 0 1].
glm::mat4 world_matrix_to_fogcl(Axes axes, const glm::mat4& world_to_x);
// A volume given in the renderer's world: centre and noise scroll speed mapped by A, the tilings
// permuted; every other field is a length, a height along up, or not spatial, and stays.
FogVolume volume_to_fogcl(Axes axes, const FogVolume& volume);

// The 16 numbers of a camera-to-world matrix in the order the renderer prints it, row by row
// (m00, m01, ..., m33), -> GLM's (column vectors: p_world = M * p_camera). unity and blender print
// column-vector matrices (translation in the last column, last row 0 0 0 1); houdini and maya
// row-vector ones (translation in the last row, last column 0 0 0 1), which are transposed here.
// Throws fogcl::Error naming the element or the rule: a non-finite element, or a matrix laid out
// the other way (the message says to transpose it). A matrix without translation fits both
// layouts; then the rotation is read as the axes say.
glm::mat4 camera_to_world_from_rows(const std::array<double, 16>& rows, Axes axes);

// Where a camera is and where its image points, in some world: unit vectors along the image's
// right, the image's up and the viewing direction, mutually orthogonal.
struct CameraFrame {
  glm::vec3 eye{0.0f};
  glm::vec3 right{1.0f, 0.0f, 0.0f};
  glm::vec3 up{0.0f, 1.0f, 0.0f};
  glm::vec3 forward{0.0f, 0.0f, 1.0f};
};

// The frame of a camera-to-world matrix (column vectors) under the axes' camera convention. The
// matrix must be rigid: finite, last row 0 0 0 1 (within 1e-6), its 3x3 part a rotation (columns
// of length 1 and pairwise orthogonal within 1e-4: no scale, no shear; determinant +1: no
// reflection). Throws fogcl::Error "camera-to-world matrix: ..." naming the rule otherwise.
CameraFrame camera_frame(const glm::mat4& camera_to_world, Axes axes);

// fogcl's pose (fogcl's world) of a frame given in the renderer's world. The frame must be finite
// and orthonormal (within 1e-4) and have the axes' handedness: cross(right, up) = forward in a
// left-handed world (unity), -forward in a right-handed one. Throws fogcl::Error otherwise.
CameraPose camera_pose(const CameraFrame& frame, Axes axes);

// Which image dimension the sensor spans (Blender's Camera.sensor_fit).
enum class SensorFit {
  automatic,   // the sensor width spans the larger image dimension (Blender's AUTO, its default)
  horizontal,  // the sensor width spans the image width
  vertical,    // the sensor height spans the image height
};
const char* to_string(SensorFit fit);
// "auto", "horizontal" or "vertical"; throws fogcl::Error naming the value otherwise.
SensorFit parse_sensor_fit(const std::string& text);

// Lens data as renderers state it (Blender's Camera.lens, sensor_width, sensor_height,
// sensor_fit). A centred frustum: lens shift is not modelled.
struct Lens {
  float focal_length_mm = 50.0f;   // finite, > 0; Blender's default 50
  float sensor_width_mm = 36.0f;   // finite, > 0; Blender's default 36
  float sensor_height_mm = 24.0f;  // finite, > 0; read only with SensorFit::vertical (Blender's rule)
  SensorFit fit = SensorFit::automatic;
};
// Throws fogcl::Error naming the field and the rule.
void validate(const Lens& lens);

// The vertical field of view [degrees] of `lens` on an image of `aspect` = width / height (square
// pixels), by Blender's rules (BKE_camera_sensor_fit, BKE_camera_sensor_size and
// BKE_camera_params_compute_viewplane in blenkernel/intern/camera.c):
//   horizontal, or automatic with aspect >= 1:  tan(fov_y / 2) = sensor_width / (2 focal) / aspect
//   vertical:                                   tan(fov_y / 2) = sensor_height / (2 focal)
//   automatic with aspect < 1 (portrait):       tan(fov_y / 2) = sensor_width / (2 focal)
// (automatic never reads the sensor height: the width spans whichever dimension is larger).
double vertical_fov_deg(const Lens& lens, double aspect);

// A renderer's perspective camera: its camera-to-world matrix (column vectors; see
// camera_to_world_from_rows for the numbers as a renderer prints them), its axes, and either lens
// data or a vertical field of view.
struct RendererCamera {
  glm::mat4 camera_to_world{1.0f};
  Axes axes = Axes::unity;
  std::optional<Lens> lens;  // when set, fov_y_deg is not read
  float fov_y_deg = 60.0f;   // [degrees], in (0, 180)
};

// fogcl's camera: the pose in fogcl's world and the vertical field of view of the frame.
struct FogclCamera {
  CameraPose pose;
  float fov_y_deg = 60.0f;
};

// The one conversion: the pose from camera_frame + camera_pose, the fov from the lens for the
// frame's aspect (width / height). Throws fogcl::Error naming the rule for a non-rigid matrix, a
// bad lens, a fov outside (0, 180) or an aspect that is not finite and > 0.
FogclCamera to_fogcl_camera(const RendererCamera& camera, float aspect);

}  // namespace fogcl
