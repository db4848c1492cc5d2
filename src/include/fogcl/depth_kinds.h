// What renderers write as depth, turned into the raw device depth the fog pass reads
// (docs/DESIGN.md §2); plain maths, in the core library. OpenEXR's Z is "distance from the
// viewer"; renderers write it as linear eye depth (along the view axis) or as radial distance from
// the eye.
#pragma once

#include <string>

#include "fogcl/camera.h"
#include "fogcl/image.h"

namespace fogcl {

const char* to_string(DepthKind kind);
// "raw", "eye" or "distance"; throws fogcl::Error naming the value otherwise.
DepthKind parse_depth_kind(const std::string& text);

// The raw device depth of the sky for this camera: 1 (conventional Z) or 0 (reversed Z).
float sky_raw_depth(const CameraParams& camera);

// The raw depth whose eye depth (docs/DESIGN.md §2) is `eye`, evaluated in double, for the camera's
// projection with (x, y) = CameraParams::zbuffer_params.xy: perspective raw = (far / eye - y) / x
// (LinearEyeDepth = far / (x raw + y)), infinite far raw = near / eye, orthographic
// raw = (eye / far - y) / x (Linear01Depth = x raw + y); clamped to [0, 1] (nearer than near: the
// near plane). Background (non-finite, <= 0 or >= far) -> sky.
double raw_from_eye_depth(double eye, const CameraParams& camera);

// Converts `depth` (the display-window frame, row 0 = top) of `kind` to raw device depth in
// place. distance: eye = distance * far / |ray(u, v)|, ray(u, v) the pixel's far-plane ray
// (bilinear in the frustum corners, kernels/fog_math.h), so that the fog pass's own
// Linear01Depth * |ray| gives back the distance (infinite far: eye = distance / |ray|, the rays
// normalised to view z = 1). raw: nothing changes. Throws fogcl::Error for distance with an
// orthographic camera (parallel rays: no distance from the eye).
void to_raw_depth(DepthImage& depth, DepthKind kind, const CameraParams& camera);

// Radial distance to linear eye depth in place (eye = distance / |ray1(u, v)|, ray1 the pixel's ray
// at view z = 1, in double, rounded once: no digit depends on near), for the volume pass, which
// reads raw or eye depth. raw and eye: nothing changes. Throws fogcl::Error for distance with an
// orthographic camera.
void to_eye_depth(DepthImage& depth, DepthKind kind, const CameraParams& camera);

}  // namespace fogcl
